"""``python -m vnrrt``: the ``vnrrt`` command line (:mod:`vnrrt.cli`)."""

import sys

from vnrrt.cli import main

sys.exit(main())
