"""``python -m gdnplan.cli``: the ``gdnplan`` command."""

from . import main

main()
