"""What `facemime call` is made of: the sender that analyses and encodes a live source
(:mod:`facemime.call.sender`) and the local server that hands its packets to browser pages
(:mod:`facemime.call.server`); the command itself is :mod:`facemime.app.call`."""
