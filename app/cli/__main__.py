"""``python -m gearsym.cli``: the same as the ``gearsym`` command."""

import sys

from . import main

sys.exit(main())
