"""``python -m gearsym``: the same as the ``gearsym`` command."""

import sys

from .cli import main

sys.exit(main())
