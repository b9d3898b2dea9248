#!/usr/bin/python3
"""The imdrive command line from a source tree or an install: python3 imdrive_cli.py --help."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from imdrive.cli import main  # noqa: E402

sys.exit(main())
