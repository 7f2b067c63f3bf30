"""``python -m schuler``: the same as the ``schuler`` command."""

from schuler.cli import main

if __name__ == "__main__":
    main()
