"""``python -m schuler``: the same as the ``schuler`` command."""

from schuler.cli import main

main()
