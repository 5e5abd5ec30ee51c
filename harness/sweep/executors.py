"""Executors for sweep chunks: a local process pool (default) or a Dask cluster.

Both run `harness.sweep.run.run_chunk` on plain-data chunks and yield (chunk, rows) as
chunks finish, in completion order, with at most a few chunks per worker in flight so
that memory stays flat and an interrupt stops quickly.  Results do not depend on the
executor: every task's initial state comes from its own seed (harness.sweep.grid).

Failures: a run that raises is caught inside the chunk (a `failed` row with its error).
A chunk that fails as a whole (a worker process died, e.g. a segfault in an engine) is
retried once; if it fails again it is split into single runs, each retried once, and a
single run that still fails is recorded as `failed` with the error.  A broken local pool
is replaced by a new one, and on the local pool a retry runs alone (nothing else in
flight), so that the chunks that merely shared the broken pool are not blamed twice.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections import deque
from collections.abc import Iterator

from ..child_processes import start_method
from .grid import Chunk
from .run import failed_rows, run_chunk

MAX_ATTEMPTS = 2


class ExecutorError(Exception):
    """The executor cannot start (e.g. no scheduler at the given address)."""


def _exit_with_parent(parent_pid: int) -> None:
    """Worker initializer: the signals left to the parent (Ctrl-C reaches the whole
    process group: the parent stops the pool; SIGTERM ends a worker at once, without the
    parent's handler inherited by fork), and exit when the parent dies (e.g. SIGKILL),
    so no orphan keeps computing after the sweep is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)

    def watch() -> None:
        while True:
            if os.getppid() != parent_pid:
                os._exit(1)
            time.sleep(0.5)

    threading.Thread(target=watch, daemon=True, name="exit-with-parent").start()


# Seconds between checks that the local pool still runs while no chunk finishes.
POOL_CHECK_S = 1.0


def _pool_running(pool) -> bool:
    """Whether the pool's manager thread (which feeds the workers and collects their
    results) runs: when it could not start its own threads (memory or thread limits)
    it dies, and no future would ever finish."""
    thread = getattr(pool, "_executor_manager_thread", None)
    return thread is None or thread.is_alive()


_thread_failures: list[BaseException] = []


def _note_thread_failure(args) -> None:
    """threading.excepthook while a local pool runs: a pool thread that dies (it could
    not start its own threads) is reported in the one-line error, not as a traceback."""
    if args.exc_value is not None:
        _thread_failures.append(args.exc_value)


# Seconds to wait for a stopped pool's manager thread to end.
POOL_JOIN_S = 30.0


def _stop(pool, *, finished: bool) -> None:
    """Shut the pool down and wait for its manager thread to end.

    Unless every chunk is `finished` (a signal, an error, or a consumer that stops
    reading ends the work early), the workers are terminated first: the rows of the
    chunks they hold would be discarded, and a pool whose manager thread died cannot
    stop its workers itself (they would wait for work for ever, and the interpreter for
    them at exit).  The manager thread is joined here, never left running: at
    interpreter exit concurrent.futures wakes every pool's manager thread without the
    lock that guards its wake-up pipe, and on Python 3.11 that races with a manager
    thread closing the pipe, which prints "OSError: [Errno 9] Bad file descriptor" after
    the command's last line (CPython gh-125451, fixed in 3.12 and 3.13 only)."""
    thread = getattr(pool, "_executor_manager_thread", None)
    processes = list((getattr(pool, "_processes", None) or {}).values())
    if not finished or not _pool_running(pool):
        for process in processes:
            process.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    if thread is not None:
        thread.join(POOL_JOIN_S)


def _cannot_run(exc: BaseException | None = None) -> ExecutorError:
    detail = f" ({type(exc).__name__}: {exc})" if exc is not None else ""
    return ExecutorError(
        f"the local worker pool cannot run{detail}: out of memory or threads (ulimit -v, "
        "ulimit -u)? try fewer --workers"
    )


class _Work:
    __slots__ = ("chunk", "attempts")

    def __init__(self, chunk: Chunk, attempts: int = 0):
        self.chunk, self.attempts = chunk, attempts


def _after_failure(work: _Work, exc: BaseException, queue: deque):
    """Requeue a failed chunk (retry, or split into single runs); return rows to record
    when it has failed for good, else None."""
    work.attempts += 1
    if work.attempts < MAX_ATTEMPTS:
        queue.appendleft(work)
        return None
    ch = work.chunk
    if len(ch.samples) > 1:
        for s in reversed(ch.samples):
            queue.appendleft(_Work(Chunk(ch.config, ch.i_gamma, ch.i_rho, (s,))))
        return None
    return failed_rows(ch, f"worker failed: {type(exc).__name__}: {exc}")


def run_local(
    chunks: list[Chunk], workers: int | None = None, fn=run_chunk
) -> Iterator[tuple[Chunk, list[dict]]]:
    """Chunks on a process pool of `workers` processes (default: all cores)."""
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    workers = workers or os.cpu_count() or 1
    ctx = mp.get_context(start_method(mp.get_all_start_methods()))

    def new_pool():
        return ProcessPoolExecutor(
            max_workers=workers,
            mp_context=ctx,
            initializer=_exit_with_parent,
            initargs=(os.getpid(),),
        )

    queue = deque(_Work(c) for c in chunks)
    limit = 2 * workers + 1
    pool = new_pool()
    inflight: dict = {}
    previous_hook = threading.excepthook
    threading.excepthook = _note_thread_failure
    finished = False
    try:
        while queue or inflight:
            while queue and len(inflight) < limit:
                # a retry runs alone, so that a crash during it is its own
                if any(x.attempts for x, _ in inflight.values()):
                    break
                if queue[0].attempts and inflight:
                    break
                w = queue.popleft()
                try:
                    inflight[pool.submit(fn, w.chunk)] = (w, pool)
                except BrokenProcessPool:
                    queue.appendleft(w)
                    _stop(pool, finished=False)
                    pool = new_pool()
                except (RuntimeError, MemoryError) as exc:  # "can't start new thread"
                    raise _cannot_run(exc) from None
            done, _ = wait(list(inflight), timeout=POOL_CHECK_S, return_when=FIRST_COMPLETED)
            if not done and not _pool_running(pool):
                raise _cannot_run(_thread_failures[-1] if _thread_failures else None)
            for fut in done:
                w, p = inflight.pop(fut)
                try:
                    rows = fut.result()
                except Exception as exc:
                    if isinstance(exc, BrokenProcessPool) and p is pool:
                        _stop(pool, finished=False)
                        pool = new_pool()
                    rows = _after_failure(w, exc, queue)
                    if rows is None:
                        continue
                yield w.chunk, rows
        finished = True
    finally:
        try:
            _stop(pool, finished=finished)
        finally:
            threading.excepthook = previous_hook


def check_scheduler(scheduler: str, timeout_s: float = 5.0) -> None:
    """ExecutorError unless the scheduler address is tcp://HOST:PORT (or HOST:PORT) and
    accepts a connection: checked before the sweep writes anything, so that a wrong
    address is one line and nothing else.  (The CLI gives no TLS credentials, and other
    protocols need packages the harness does not install.)"""
    import socket
    from urllib.parse import urlsplit

    try:
        url = urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}")
        host, port = (url.hostname, url.port) if url.scheme == "tcp" else (None, None)
    except ValueError:  # e.g. an unclosed IPv6 bracket, a port beyond 65535
        host, port = None, None
    if not host or port is None:
        raise ExecutorError(f"--scheduler {scheduler!r} is not an address like tcp://HOST:PORT")
    try:
        socket.create_connection((host, port), timeout=timeout_s).close()
    except OSError as exc:
        raise ExecutorError(
            f"cannot connect to the Dask scheduler at {scheduler}: {exc.strerror or exc}"
        ) from None
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        raise ExecutorError(
            f"the Dask scheduler at {scheduler} needs dask.distributed here: "
            "pip install 'euler-disk-harness[dask]'"
        )


def run_dask(
    chunks: list[Chunk], scheduler: str, fn=run_chunk
) -> Iterator[tuple[Chunk, list[dict]]]:
    """Chunks on a dask.distributed cluster at `scheduler` (e.g. tcp://host:8786).

    The workers must be able to import this package (`harness`, `reference`): install
    it on every worker's Python.  Results come back to this process, which alone writes
    the store, so the workers need no access to --out.  The cluster's own size decides
    the parallelism (--workers is for the local pool only)."""
    from distributed import Client

    try:
        client = Client(scheduler, timeout="20s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ExecutorError(f"cannot connect to the Dask scheduler at {scheduler}: {exc}") from None
    return _dask_results(client, chunks, fn)


def _dask_results(client, chunks: list[Chunk], fn) -> Iterator[tuple[Chunk, list[dict]]]:
    from distributed import as_completed

    try:
        n_workers = max(
            1, sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
        )
        limit = 2 * n_workers + 1
        queue = deque(_Work(c) for c in chunks)
        inflight: dict = {}
        ac = as_completed()

        def submit(w: _Work) -> None:
            fut = client.submit(fn, w.chunk, pure=False, retries=0)
            inflight[fut.key] = w
            ac.add(fut)

        while queue and len(inflight) < limit:
            submit(queue.popleft())
        while inflight:
            fut = next(ac)
            w = inflight.pop(fut.key)
            try:
                rows = fut.result()
            except Exception as exc:
                rows = _after_failure(w, exc, queue)
            finally:
                fut.release()
            if rows is not None:
                yield w.chunk, rows
            while queue and len(inflight) < limit:
                submit(queue.popleft())
    finally:
        client.close()
