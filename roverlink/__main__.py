"""`python -m roverlink`: the same as the `roverlink` command."""

import sys

from roverlink.cli import main

sys.exit(main())
