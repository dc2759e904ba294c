"""One module per ``gatetherm`` sub-command; each has ``register(subparsers)``.

``register`` adds its parser and sets ``func=run`` where ``run(args) -> int``.
These are the thin outer layer: they read input, call the numerics, write files.
"""
