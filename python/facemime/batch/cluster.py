"""The Dask cluster a batch runs on: a local one (one single-threaded worker process per job)
or an existing one reached at a scheduler's address."""

from __future__ import annotations

import logging
import re
from collections.abc import Iterator
from contextlib import contextmanager
from importlib.util import find_spec
from typing import TYPE_CHECKING

from facemime.batch.worker import THREAD_VARIABLES
from facemime.errors import FacemimeError, InvalidInputError

if TYPE_CHECKING:
    from distributed import LocalCluster

#: Seconds to wait for an existing scheduler to answer.
CONNECT_SECONDS = 5
_ADDRESS = re.compile(r"^(tcp|tls|ucx|ws|wss)://(\[[0-9a-fA-F:]+\]|[A-Za-z0-9.-]+):(\d{1,5})$")


class ClusterError(FacemimeError, ConnectionError):
    """The Dask cluster cannot be started or reached."""


def check_address(address: str) -> None:
    """Refuse a scheduler address that is not ``PROTOCOL://HOST:PORT`` (tcp, tls, ucx, ws, wss):
    raise :class:`~facemime.errors.InvalidInputError`.

    Parameters
    ----------
    address
        The scheduler's address, e.g. ``tcp://10.0.0.5:8786``; the port must be 1-65535 and an
        IPv6 host be written in brackets.
    """
    m = _ADDRESS.match(address)
    if m is None or not 0 < int(m.group(3)) < 65536:
        raise InvalidInputError(f"the scheduler address must look like tcp://HOST:PORT, got {address!r}")


def local_cluster(jobs: int) -> LocalCluster:
    """A new local Dask cluster.

    Parameters
    ----------
    jobs
        How many worker processes it has.

    Returns
    -------
    distributed.LocalCluster
        ``jobs`` worker processes, one thread each, their BLAS/OpenMP pools set to one thread, logs
        below errors silenced, the dashboard on a free port.
    """
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=jobs,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=logging.ERROR,
        env=dict.fromkeys(THREAD_VARIABLES, "1"),
    )


@contextmanager
def open_client(jobs: int, scheduler: str | None = None, retries: int = 2) -> Iterator[object]:
    """A Dask client, closed (with the local cluster it started, if any) when the ``with`` block
    ends. Logs below errors are silenced; the dashboard is served only when bokeh is installed.
    :class:`ClusterError` when the cluster cannot be started or the scheduler not reached within
    :data:`CONNECT_SECONDS`.

    Parameters
    ----------
    jobs
        Worker processes of the new local cluster, each with one thread and its BLAS/OpenMP pools
        set to one thread; unused with ``scheduler``.
    scheduler
        The address (``PROTOCOL://HOST:PORT``, see :func:`check_address`) of a running Dask
        scheduler to attach to instead; None starts a local cluster.
    retries
        How many times the local cluster retries a task whose worker died (the scheduler's
        ``allowed-failures``); a running ``scheduler``'s own setting applies instead.

    Yields
    ------
    distributed.Client
        The client, on the local cluster or attached to ``scheduler``.
    """
    import dask
    from distributed import Client

    if scheduler is not None:
        check_address(scheduler)
    logging.getLogger("distributed").setLevel(logging.ERROR)
    with dask.config.set({"distributed.scheduler.allowed-failures": retries}):
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout=CONNECT_SECONDS)
            except (OSError, TimeoutError) as e:
                raise ClusterError(
                    f"cannot reach the Dask scheduler at {scheduler}: {' '.join(str(e).split()) or type(e).__name__}"
                ) from None
            with client:
                yield client
            return
        try:  # the scheduler's web server (the dashboard with bokeh) on a free port
            cluster = local_cluster(jobs)
        except (OSError, TimeoutError) as e:
            raise ClusterError(f"cannot start a local Dask cluster: {' '.join(str(e).split())}") from None
        with cluster, Client(cluster) as client:
            yield client


def dashboard_link(client: object) -> str | None:
    """The address of the cluster's dashboard.

    Parameters
    ----------
    client
        A ``distributed.Client``, as :func:`open_client` yields.

    Returns
    -------
    str or None
        The dashboard's URL; None when the scheduler serves none (bokeh missing) or the client
        cannot tell.
    """
    if find_spec("bokeh") is None:  # the scheduler serves no dashboard without it
        return None
    try:
        if "dashboard" not in client.scheduler_info().get("services", {}):  # type: ignore[attr-defined]
            return None
        return client.dashboard_link  # type: ignore[attr-defined]
    except Exception:  # noqa: BLE001 (a link is a convenience)
        return None
