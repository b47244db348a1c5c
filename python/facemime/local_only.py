"""Who may use facemime's web servers on this machine (``facemime view``, ``facemime call``): they
listen on 127.0.0.1 only, and answer only requests addressed to this machine by name, against DNS
rebinding (a page of another site that has its name resolve to 127.0.0.1 sends that name as
``Host``), and, where the browser says which page sent a request (``Origin``), only the server's
own pages (a page served on another port of this machine is another origin).
"""

from __future__ import annotations

import re
from collections.abc import Sequence

#: This machine's names, as a browser addresses a server bound to 127.0.0.1.
NAMES = r"(?:127\.0\.0\.1|localhost)"


def addressed_here(hosts: Sequence[str], origins: Sequence[str], port: int) -> bool:
    """Whether a request may be answered by a server on 127.0.0.1:``port``; names are matched
    without regard to case.

    Parameters
    ----------
    hosts
        The values of the request's ``Host`` headers: there must be exactly one, this machine's
        name (``127.0.0.1`` or ``localhost``) with ``port`` or with no port.
    origins
        The values of its ``Origin`` headers: none, or one that is ``http://``, this machine's
        name and ``port``.
    port
        The TCP port the server listens on.

    Returns
    -------
    bool
        True when the request may be answered, False when it must be refused (403).

    Examples
    --------
    >>> addressed_here(["localhost:8765"], ["http://127.0.0.1:8765"], 8765)
    True
    >>> addressed_here(["127.0.0.1:8765"], ["http://localhost:3000"], 8765)
    False
    """
    return (
        len(hosts) == 1
        and re.fullmatch(rf"{NAMES}(?::{port})?", hosts[0].strip(), re.IGNORECASE) is not None
        and len(origins) <= 1
        and all(re.fullmatch(rf"http://{NAMES}:{port}", o.strip(), re.IGNORECASE) for o in origins)
    )
