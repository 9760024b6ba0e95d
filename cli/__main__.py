"""``python -m rawehelix.cli``: the ``rawehelix`` command without its script."""

from rawehelix.cli.main import main

if __name__ == "__main__":
    main()
