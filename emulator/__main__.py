"""`python -m emulator`: the same as `roverlink emulate`."""

import sys

from emulator.cli import main

sys.exit(main())
