"""Newton's equations per body, the mesh coordinates, the structure beyond torsion, and the
non-dimensional form."""
