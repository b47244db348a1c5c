"""``python -m facemime``: the same as the ``facemime`` command."""

from facemime.cli.main import main

main()
