"""``python -m peridyn ...``: the same as the ``peridyn`` command."""

from peridyn.cli import main

raise SystemExit(main())
