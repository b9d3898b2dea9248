"""python3 -m imdrive: the command line (imdrive/cli.py)."""
import sys

from .cli import main

sys.exit(main())
