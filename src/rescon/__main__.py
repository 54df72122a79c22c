"""``python -m rescon``: the same command line as the ``rescon`` script."""

import sys

from .cli import main

sys.exit(main())
