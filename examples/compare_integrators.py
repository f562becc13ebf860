"""Moved into the package: ``python -m deforma.examples integrators`` (src/deforma/examples/integrators.py).

This file stays so that ``python examples/compare_integrators.py [options]`` keeps working.
"""

import sys

from deforma.examples.integrators import main

if __name__ == "__main__":
    sys.exit(main())
