"""Progress bars for long work: rich, on stderr, shown only when stderr is a terminal."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

T = TypeVar("T")


def track(items: Iterable[T], total: int | None, description: str) -> Iterator[T]:
    """Iterate over ``items`` with a progress bar, on stderr and only when stderr is a terminal
    (the bar is removed when the iteration ends).

    Parameters
    ----------
    items
        What to iterate over.
    total
        How many items there are, for the bar's count and time left; None when unknown.
    description
        The bar's label.

    Yields
    ------
    T
        Each of ``items`` in turn, unchanged.
    """
    if not sys.stderr.isatty():
        yield from items
        return
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(description, total=total)
        for item in items:
            yield item
            bar.advance(task)
