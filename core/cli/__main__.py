"""``python -m gatetherm.cli``: the same as the ``gatetherm`` command."""
from gatetherm.cli import console

console()
