"""``python -m inertia_tool``: the same as the ``inertia-tool`` command."""

import sys

from .cli import main

sys.exit(main())
