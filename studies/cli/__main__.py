"""``python -m gatetherm.studies.cli``: the same as the ``gatetherm`` command."""
import sys

from gatetherm.studies.cli import main

sys.exit(main())
