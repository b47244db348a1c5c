"""The ``facemime`` command."""
