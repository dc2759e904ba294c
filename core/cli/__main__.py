"""``python -m gatetherm.cli``: the same as the ``gatetherm`` command."""
import sys

from gatetherm.cli import main

sys.exit(main())
