"""``python -m deforma.examples [NAME [options]]``: list the examples or run one."""

import sys

from . import main

sys.exit(main())
