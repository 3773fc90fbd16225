"""``python -m plansim.cli``: the ``plansim`` command."""

import sys

from plansim.cli import main

sys.exit(main())
