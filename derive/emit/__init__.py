"""From a Model to files: generated Python/CasADi/C and the audit pages of docs/."""
