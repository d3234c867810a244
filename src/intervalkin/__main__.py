"""``python -m intervalkin`` runs the command line."""

import sys

from intervalkin.app.cli import main

sys.exit(main())
