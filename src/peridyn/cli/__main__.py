"""``python -m peridyn.cli``: the ``peridyn`` command without its console script."""

import sys

from peridyn.cli import main

sys.exit(main())
