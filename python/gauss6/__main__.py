"""`python -m gauss6`: the gauss6 command (gauss6.cli)."""
import sys

from .cli import main

sys.exit(main())
