"""``python -m plough`` is the ``plough`` command."""

import sys

from plough.cli import main

sys.exit(main())
