"""What ``facemime live`` is made of: the VMC protocol's messages and their sender."""
