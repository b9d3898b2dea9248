#!/usr/bin/python3
"""The imdrive command line from a source tree or an install: python3 imdrive_cli.py --help."""
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
sys.path.insert(0, str(here))  # the source tree: tools/python/imdrive
# Installed as PREFIX/bin/imdrive: the package is in PREFIX/lib/python3/dist-packages, which
# python3 searches by itself only for the prefix /usr. It goes first, before the line above.
installed = here.parent / "lib" / "python3" / "dist-packages"
if (installed / "imdrive").is_dir():
    sys.path.insert(0, str(installed))
from imdrive.cli import main  # noqa: E402

sys.exit(main())
