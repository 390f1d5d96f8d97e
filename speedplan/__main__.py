"""``python -m speedplan``: the ``speedplan`` command line (see `speedplan.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
