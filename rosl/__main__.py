"""``python -m rosl``: the same as the ``rosl`` command."""

import sys

from rosl.cli.main import main

sys.exit(main())
