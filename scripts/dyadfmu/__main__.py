"""``python -m dyadfmu``: the ``dyadfmu`` command."""

from .cli import main

raise SystemExit(main())
