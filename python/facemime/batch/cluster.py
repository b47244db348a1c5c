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
    """Refuse a scheduler address that is not ``PROTOCOL://HOST:PORT`` (tcp, tls, ucx, ws, wss)."""
    m = _ADDRESS.match(address)
    if m is None or not 0 < int(m.group(3)) < 65536:
        raise InvalidInputError(f"the scheduler address must look like tcp://HOST:PORT, got {address!r}")


def local_cluster(jobs: int) -> LocalCluster:
    """A new ``distributed.LocalCluster`` of ``jobs`` worker processes, one thread each, their
    BLAS/OpenMP pools set to one thread, logs below errors silenced, the dashboard on a free port."""
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
    """A ``distributed.Client``: on a new local cluster of ``jobs`` worker processes, each with
    one thread and its BLAS/OpenMP pools set to one thread, that retries a task whose worker died
    ``retries`` times (the scheduler's ``allowed-failures``); or attached to the running
    ``scheduler`` (its own setting of retries applies). Logs below errors are silenced; the
    dashboard is served only when bokeh is installed."""
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
    """The address of the cluster's dashboard, None when it serves none (bokeh missing)."""
    if find_spec("bokeh") is None:  # the scheduler serves no dashboard without it
        return None
    try:
        if "dashboard" not in client.scheduler_info().get("services", {}):  # type: ignore[attr-defined]
            return None
        return client.dashboard_link  # type: ignore[attr-defined]
    except Exception:  # noqa: BLE001 (a link is a convenience)
        return None
