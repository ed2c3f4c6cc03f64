"""``python -m vnrrt``: the ``vnrrt`` command line (:mod:`vnrrt.cli.main`)."""

import sys

from vnrrt.cli.main import main

sys.exit(main())
