"""``python -m gdnplan``: the ``gdnplan`` command (as ``python -m gdnplan.cli``)."""

from .cli import main

main()
