"""``python -m armdyn ...`` is the ``armdyn`` command."""

import sys

from .cli import main

sys.exit(main())
