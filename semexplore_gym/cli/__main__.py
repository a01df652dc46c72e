"""``python -m semexplore_gym.cli``: the ``semexplore`` command without its console script."""

import sys

from semexplore_gym.cli import main

sys.exit(main())
