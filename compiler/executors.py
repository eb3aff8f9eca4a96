"""Where the work of a campaign is done: in this process, on a pool of local processes,
or on a Dask cluster (`--scheduler tcp://HOST:8786`), each a `concurrent.futures.Executor`
(Dask's client offers one), so that `rl1c sim --runs` and `rl1c fuzz` have one code path
for all three.

Dask's `distributed` is an optional extra (`pip install 'rl1[cluster]'`), imported only
when a scheduler is given. Its workers and its scheduler (which unpickles each task) need
this rl1 installed and nothing else: what they run carries its inputs
(compiler/campaign.py's Task holds the program and the world).
"""

from __future__ import annotations

import asyncio
import contextlib
import ctypes
import functools
import hashlib
import logging
import multiprocessing
import os
import pickle
import signal
import struct
import subprocess
import sys
import threading
import time
import weakref
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, Future, InvalidStateError, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import IO, TYPE_CHECKING, Any, ParamSpec, TypeVar

from rl1 import vm

if TYPE_CHECKING:
    from distributed import Client

CONNECT_TIMEOUT = 5  # s: an unreachable scheduler is said in a few seconds, and a lost
# one once its client has tried as long to reconnect
WATCH_EVERY = 0.5  # s between looks at whether a cluster's client has given up
MANNED_EVERY = 2.0  # s between asks whether a cluster with work waiting has workers
UNMANNED_AFTER = 10.0  # s without one before it is said: a nanny restarts its worker in
# a few seconds
PARENT_WATCH_EVERY = 0.5  # s between a local worker's looks at whether its parent
# has ended, once it was sent SIGINT or SIGTERM
EXTRA = "cluster"  # pyproject.toml's extra that installs `distributed`

P = ParamSpec("P")
T = TypeVar("T")


class Unavailable(Exception):
    """The executor asked for cannot be had: its message says why and what to do (an
    error's message, without the word `error:` the command line puts first)."""


class ClusterLost(Exception):
    """The work a cluster had not finished when it could no longer do it: the connection
    to its scheduler lost for good, or a worker that joined later runs another rl1 (its
    message says which)."""


class TaskProcessEnded(Exception):
    """A task given a process of its own on a cluster's worker (`isolated`), which ended
    before it answered (by a signal, or an exit): what it ran ended it, as a local pool's
    worker would have been ended, and the cluster's worker goes on."""


class TaskUnreadable(Unavailable):
    """A task that its process of its own could not read (unpickle): the code it names
    cannot be imported there as it is here. The installation's doing, not the task's."""


class _OtherRl1(Exception):
    """Raised on a worker whose rl1 is not the client's; its argument is the worker's
    address."""


@dataclass(frozen=True, slots=True)
class Workers:
    """An executor (None: the work is done in this process), how many tasks it makes at
    once (a cluster: its workers' threads when it was reached, 0 while none has joined),
    and the errors of a task lost with its worker, which can be submitted again (a
    pool whose worker died, unless made again, is broken instead:
    concurrent.futures.BrokenExecutor)."""

    executor: Executor | None
    slots: int
    lost: tuple[type[BaseException], ...] = ()


def ignore_interrupts() -> None:
    """A local worker's start: SIGINT and SIGTERM reach the whole process group (Ctrl-C,
    a CI job's timeout) or every process of a command line (`pkill -f`), and the parent,
    which takes them, stops its workers itself, keeping their work: a worker ended by
    one would be a worker lost (a pool ends its workers with SIGKILL instead: `_Worker`).
    Once sent one, a worker ends when its parent does, as a parent that does not take
    them (a test, a script) would have it."""
    parent = os.getppid()
    watching = False

    def heard(signum: int, frame: FrameType | None) -> None:
        nonlocal watching
        if not watching:
            watching = True
            threading.Thread(target=_end_with, args=(parent, signum), daemon=True).start()

    signal.signal(signal.SIGINT, heard)
    signal.signal(signal.SIGTERM, heard)


def _end_with(parent: int, signum: int) -> None:
    """Ends this process, as the signal `signum` would have, once `parent` has ended
    (and this process is another's child)."""
    while os.getppid() == parent:
        time.sleep(PARENT_WATCH_EVERY)
    os._exit(128 + signum)


class _Worker(multiprocessing.Process):
    """A pool's process, of the platform's start method: a pool ends its workers with
    SIGTERM when one dies (the queues may be in a dirty state), which they ignore, so
    they are ended with SIGKILL."""

    def terminate(self) -> None:
        self.kill()


class _Workers(multiprocessing.context.DefaultContext):
    """The platform's multiprocessing context, making `_Worker`s."""

    Process = _Worker


@contextmanager
def workers(jobs: int, scheduler: str | None = None, *,
            lost: Callable[[], None] | None = None, isolated: bool = False,
            unmanned: Callable[[], None] | None = None) -> Iterator[Workers]:
    """The workers of a campaign: the Dask cluster of `scheduler` when given, else `jobs`
    local processes (this process alone for 1, unless `isolated`: work that may end the
    process doing it, such as the C VM's, then has one of its own, and on a cluster each
    task has a process of its own on its worker, `TaskProcessEnded` when it ends, so
    that the worker lives on). Given `lost`, a local pool one of whose processes dies is
    made again (`Renewed`), else it is broken for good; `lost()` is called each time a
    worker is lost with its work: a local pool's process, a cluster's (a task failed
    with KilledWorker), or an isolated task's process. A cluster whose workers have all
    gone while work waits (killed, without a nanny to start them again) waits for one,
    calling `unmanned` each time it is left without. Unavailable when `distributed` is
    not installed or the scheduler cannot be reached. On leaving, the work not yet done
    is cancelled."""
    if scheduler is not None:
        with _cluster(scheduler, unmanned, lost, isolated) as cluster:
            yield cluster
        return
    if jobs == 1 and not isolated:
        yield Workers(None, 1)
        return
    pool: Executor = _pool(jobs) if lost is None else Renewed(jobs, lost)
    try:
        yield Workers(pool, jobs, () if lost is None else (BrokenProcessPool,))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _pool(jobs: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(max_workers=jobs, initializer=ignore_interrupts,
                               mp_context=_Workers(multiprocessing.get_context()))


class Renewed(Executor):
    """`jobs` local processes that outlive the death of one, as a Dask cluster outlives a
    worker's: a ProcessPoolExecutor whose process dies is broken for good, failing every
    task in flight with BrokenProcessPool (the one that killed it and those merely beside
    it alike), so the first task submitted after that goes to a new pool, which then
    takes every task (a campaign submits the lost ones again, a run a task), and
    `renewed` is called."""

    def __init__(self, jobs: int, renewed: Callable[[], None]) -> None:
        self._jobs = jobs
        self._renewed = renewed
        self._pool = _pool(jobs)
        self._futures: weakref.WeakSet[Future[Any]] = weakref.WeakSet()  # of this pool

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        try:
            future = self._pool.submit(fn, *args, **kwargs)
        except BrokenProcessPool as broken:
            self._renew(broken)
            future = self._pool.submit(fn, *args, **kwargs)
        self._futures.add(future)
        return future

    def _renew(self, broken: BrokenProcessPool) -> None:
        old, self._pool = self._pool, _pool(self._jobs)
        old.shutdown(wait=True)  # its thread fails its tasks and ends its processes
        # A task submitted while the old pool was being found broken can be missed by
        # that thread, and wait for ever: failed here, it is lost as the others were.
        for future in list(self._futures):
            with contextlib.suppress(InvalidStateError):  # finished, or failed already
                future.set_exception(broken)
        self._futures = weakref.WeakSet()
        self._renewed()

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        self._pool.shutdown(wait=wait, cancel_futures=cancel_futures)


@contextmanager
def _cluster(address: str, unmanned: Callable[[], None] | None,
             lost: Callable[[], None] | None, isolated: bool) -> Iterator[Workers]:
    try:
        from distributed import Client
        from distributed.scheduler import KilledWorker
    except ImportError as error:
        raise Unavailable(
            f"--scheduler needs Dask's `distributed`, which is not installed here "
            f"({error})\n  = help: install the extra `{EXTRA}`: pip install 'rl1[{EXTRA}]' "
            "(or pip install distributed), on this machine and on the workers'") from None
    client = _connect(Client, address)
    # The client logs, with tracebacks, what the campaign says in a line of its own;
    # Dask's configuration gives some of its loggers a level of their own.
    for name in ["distributed", "tornado", *logging.root.manager.loggerDict]:
        if name.partition(".")[0] in ("distributed", "tornado"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
    try:
        _same_rl1(client, address)
        slots = _threads(client, address)
    except Unavailable:
        client.close()  # type: ignore[no-untyped-call]
        raise
    try:
        losses = (KilledWorker, TaskProcessEnded) if isolated else (KilledWorker,)
        yield Workers(_Watched(client, address, unmanned, lost, isolated, losses), slots,
                      losses)
    finally:
        # The scheduler forgets the client's tasks left, and cancels them.
        client.close()  # type: ignore[no-untyped-call]


@functools.cache
def sources_digest() -> str:
    """The SHA-256 of the Python sources of rl1's compiler and VM as installed here: two
    machines with one digest make the same runs; a worker with another runs another
    rl1, whose results would not be this one's (or an internal error)."""
    digest = hashlib.sha256()
    for package in (Path(__file__).parent, Path(vm.__file__).parent):
        for path in sorted(package.rglob("*.py")):
            digest.update(path.relative_to(package.parent).as_posix().encode() + b"\0")
            digest.update(path.read_bytes())
    return digest.hexdigest()


def _same_rl1(client: Client, address: str) -> None:
    """Unavailable when the scheduler, or a worker of the cluster now, runs another rl1
    or none (a worker joining later is checked by each task it is given: `_checked`).
    The scheduler unpickles each task, and so needs the classes it holds: without them,
    Dask fails every task with a RuntimeError that names no cause."""
    try:
        scheduler = client.run_on_scheduler(sources_digest)  # type: ignore[no-untyped-call]
    except OSError as error:  # the scheduler gone since it was reached
        raise _connection_lost(address, error) from None
    except Exception as error:  # such as a scheduler without rl1, which cannot unpickle it
        raise Unavailable(f"the Dask scheduler at {address} cannot read rl1's tasks "
                          f"({type(error).__name__}: {error})\n  = help: install this rl1 "
                          "on the scheduler's machine too (it unpickles each task), and "
                          "restart the scheduler") from None
    if scheduler != sources_digest():
        raise Unavailable(
            f"the Dask scheduler at {address} runs another rl1 than this one (its sources "
            "differ), which may read rl1's tasks otherwise\n  = help: install the same rl1 "
            "there, and restart the scheduler")
    try:
        theirs: dict[str, str | BaseException] = client.run(sources_digest, on_error="return")
    except OSError as error:  # the scheduler gone since it was reached
        raise _connection_lost(address, error) from None
    for answer in theirs.values():
        # An OSError is a worker gone since (killed, or ended): it runs nothing.
        if isinstance(answer, BaseException) and not isinstance(answer, OSError):
            # such as a worker without rl1, which cannot run it
            raise Unavailable(f"the workers of the Dask scheduler at {address} cannot run "
                              f"rl1 ({type(answer).__name__}: {answer})\n  = help: install "
                              "this rl1 on each worker's machine")
    others = sorted(worker for worker, digest in theirs.items()
                    if isinstance(digest, str) and digest != sources_digest())
    if others:
        raise Unavailable(
            f"the Dask workers {', '.join(others)} of the scheduler at {address} run "
            "another rl1 than this one (its sources differ), whose runs would not be this "
            "rl1's\n  = help: install the same rl1 there, and restart those workers")


def _connect(client: type[Client], address: str) -> Client:
    from distributed.comm.core import connect

    async def reach() -> None:
        comm = await connect(address, timeout=CONNECT_TIMEOUT)  # type: ignore[no-untyped-call]
        await comm.close()

    try:
        # Reached first with a connection of its own: a Client that fails to connect
        # leaves an object whose collection blocks for twice the timeout and then prints
        # a traceback.
        asyncio.run(reach())
        return client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, ValueError) as error:  # no server there, or a wrong address
        raise _unreachable(address, str(error)) from None
    except Exception:  # such as a length of exabytes read from the first bytes
        raise _unreachable(address, "the server there answered, but not as a Dask "
                           "scheduler") from None


def _unreachable(address: str, why: str) -> Unavailable:
    return Unavailable(
        f"cannot reach a Dask scheduler at {address} ({why})\n"
        f"  = help: start one there (`dask scheduler`, then `dask worker {address}` on "
        "each machine), or give its address as tcp://HOST:8786")


class _Watched(Executor):
    """The executor of a Dask client, whose work not yet finished fails with
    ClusterLost once the client gives up reconnecting to its scheduler: Dask's own
    futures are then cancelled, or wait for ever. While work waits, it asks every
    MANNED_EVERY seconds whether the cluster has workers, and calls `unmanned` when it
    has had none for UNMANNED_AFTER seconds (again only once some have joined since).
    `isolated`: each task runs in a process of its own on its worker (`in_own_process`).
    `lost()` is called when a task fails with an error of `losses`, once a worker (the
    tasks it had fail together)."""

    def __init__(self, client: Client, address: str,
                 unmanned: Callable[[], None] | None = None,
                 lost: Callable[[], None] | None = None, isolated: bool = False,
                 losses: tuple[type[BaseException], ...] = ()) -> None:
        self._client = client
        # Not pure: a task submitted again after its worker died is a new one, not the
        # failed one remembered under the same key.
        self._executor: Executor = client.get_executor(  # type: ignore[no-untyped-call]
            pure=False)
        self._address = address
        self._unmanned = unmanned
        self._lost_one = lost
        self._workers_lost: set[str] = set()  # the addresses of those said
        self._isolated = isolated
        self._losses = losses
        self._futures: weakref.WeakSet[Future[Any]] = weakref.WeakSet()
        threading.Thread(target=self._watch, daemon=True).start()

    def _lost(self) -> bool:
        return self._client.status in ("closing", "closed")

    def _watch(self) -> None:
        asked = time.monotonic()
        manned = asked  # when the cluster last had workers, or no work waited
        said = False  # that it has none
        while not self._lost():
            time.sleep(WATCH_EVERY)
            if self._unmanned is not None and time.monotonic() - asked >= MANNED_EVERY:
                asked = time.monotonic()
                if self._manned():
                    manned, said = asked, False
                elif not said and asked - manned >= UNMANNED_AFTER:
                    said = True
                    self._unmanned()
        for future in list(self._futures):
            self._fail(future)

    def _manned(self) -> bool:
        """Whether the cluster has workers, or no work waits for one."""
        if all(future.done() for future in list(self._futures)):
            return True
        try:
            return bool(self._client.nthreads())  # type: ignore[no-untyped-call]
        except Exception:  # such as the connection lost, which _lost tells
            return True

    def _fail(self, future: Future[Any]) -> None:
        with contextlib.suppress(InvalidStateError):  # finished, or cancelled
            future.set_exception(ClusterLost(
                f"the connection to the Dask scheduler at {self._address} was lost"))

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        future: Future[T] = Future()
        self._futures.add(future)
        if self._lost():  # given up: Dask's future would wait for ever
            self._fail(future)
            return future
        dask = self._executor.submit(_checked, sources_digest(), self._isolated, fn, *args,
                                     **kwargs)
        future.add_done_callback(lambda done: done.cancelled() and dask.cancel())
        dask.add_done_callback(lambda done: self._pass(done, future))
        if self._lost():  # given up since, perhaps after the watcher's last look
            self._fail(future)
        return future

    def _pass(self, dask: Future[T], future: Future[T]) -> None:
        """Give `future` the outcome of Dask's: cancelled only by us (through
        `future`), so a cancellation of Dask's own is the client giving up."""
        if dask.cancelled():
            self._fail(future)
            return
        with contextlib.suppress(InvalidStateError):  # cancelled by the campaign
            error = dask.exception()
            if isinstance(error, _OtherRl1):
                error = ClusterLost(
                    f"the Dask worker {error.args[0]}, which joined the scheduler at "
                    f"{self._address} after the start, runs another rl1 than this one (its "
                    "sources differ; install the same rl1 there, and restart that worker)")
            if error is None:
                future.set_result(dask.result())
                return
            if isinstance(error, self._losses):
                self._say_lost(error)
            future.set_exception(error)

    def _say_lost(self, error: BaseException) -> None:
        """`lost()` for the worker of `error`, unless said already (KilledWorker names the
        worker that died last; each TaskProcessEnded is a process of its own)."""
        worker = getattr(getattr(error, "last_worker", None), "address", None)
        if worker is not None:
            if worker in self._workers_lost:
                return
            self._workers_lost.add(worker)
        if self._lost_one is not None:
            self._lost_one()

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        self._executor.shutdown(wait=False)  # the client's close cancels what is left


def _checked(digest: str, isolated: bool, fn: Callable[P, T], /, *args: P.args,
             **kwargs: P.kwargs) -> T:
    """`fn(*args, **kwargs)` on a cluster's worker (in a process of its own when
    `isolated`, which first imports the modules the worker preloaded, as they may set up
    what the task runs), once it is known to run the client's rl1 (whose sources have
    `digest`): the workers were checked when the campaign began, but one may join
    later."""
    from distributed import get_worker

    if sources_digest() != digest:
        raise _OtherRl1(get_worker().address)
    if not isolated:
        return fn(*args, **kwargs)
    # Those given as modules (not files), which a process finds on the worker's path;
    # their `dask_setup` is not called there: Dask calls it with a worker, which that
    # process is not (spec/optimization.md).
    preloaded = tuple(preload.name for preload in get_worker().preloads
                      if getattr(getattr(preload, "module", None), "__name__", None)
                      == preload.name)
    try:
        return in_own_process(preloaded, fn, *args, **kwargs)
    except TaskUnreadable as error:
        raise TaskUnreadable(f"on the Dask worker {get_worker().address}, {error}") from None


# A spawned process's start: this process's sys.path (so that it imports what this one
# would, test modules and all), then the call, each pickled on its standard input.
_SPAWNED = ("import pickle, sys; sys.path[:] = pickle.load(sys.stdin.buffer); "
            "target, args = pickle.load(sys.stdin.buffer); target(*args)")


def spawn(target: Callable[..., object], *args: object, keep: tuple[int, ...] = ()
          ) -> subprocess.Popen[bytes]:
    """A new Python process calling `target(*args)` (pickled) and ending: started afresh
    with this process's sys.path, never forked from this one, so that it can be made
    from any thread of a process of many (a Dask worker's), where a fork copies locks
    that other threads hold and Python 3.12 warns of it. `keep`: the file descriptors
    it inherits. Its start costs some 0.2 to 0.5 s of imports, where a fork costs
    milliseconds (bench/own_process.py)."""
    # Pickled before the process starts: a call that cannot be pickled is raised here,
    # not left to a process that would end on a half-read input and never be waited for.
    start = pickle.dumps(sys.path) + pickle.dumps((target, args))
    process = subprocess.Popen([sys.executable, "-c", _SPAWNED], stdin=subprocess.PIPE,
                               pass_fds=keep)
    assert process.stdin is not None
    with contextlib.suppress(BrokenPipeError), process.stdin:  # ended already: its
        # status says how
        process.stdin.write(start)
    return process


# Linux's prctl options (linux/prctl.h)
PR_SET_PDEATHSIG = 1
PR_SET_CHILD_SUBREAPER = 36


@contextmanager
def orphans_ended() -> Iterator[None]:
    """While inside, this process adopts the orphans among its descendants, where init
    would (Linux's child subreaper); on leaving, it kills and reaps every child it has
    that it did not have on entering, and those that these leave in turn: so a command
    run inside, whose process group is killed at its end, leaves no process it started
    in a session of its own (setsid), outside that group. Nothing is adopted where that
    cannot be (not Linux, no /proc listing the children). Only for a thread whose
    process starts no other processes meanwhile: those would be taken for orphans."""
    adopting = _adopt_orphans(True)
    before = _children() if adopting else set()
    try:
        yield
    finally:
        if adopting:
            _end_adopted(before)
            _adopt_orphans(False)


def _adopt_orphans(adopt: bool) -> bool:
    """Whether this process now adopts (or no longer adopts) its descendants' orphans."""
    return os.path.exists(f"/proc/self/task/{threading.get_native_id()}/children") \
        and _prctl(PR_SET_CHILD_SUBREAPER, adopt)


def _prctl(option: int, value: int) -> bool:
    """Whether Linux's prctl set `option` of this process to `value` (False elsewhere)."""
    if not sys.platform.startswith("linux"):
        return False
    libc = ctypes.CDLL(None, use_errno=True)
    status: int = libc.prctl(ctypes.c_int(option), ctypes.c_ulong(value), ctypes.c_ulong(0),
                             ctypes.c_ulong(0), ctypes.c_ulong(0))
    return status == 0


def _children() -> set[int]:
    """This process's children now, those of each of its threads."""
    children: set[int] = set()
    for thread in os.listdir("/proc/self/task"):
        with contextlib.suppress(OSError), \
                open(f"/proc/self/task/{thread}/children", encoding="ascii") as listed:
            # (suppressed: a thread that ended since)
            children.update(int(pid) for pid in listed.read().split())
    return children


def _end_adopted(before: set[int]) -> None:
    """Kill and reap the children this process has beyond `before` (and, as each ends,
    the orphans it leaves in turn)."""
    spared = set(before)
    while adopted := _children() - spared:
        for pid in adopted:
            try:
                os.kill(pid, signal.SIGKILL)
            except PermissionError:  # another user's (setuid): it cannot be ended
                spared.add(pid)
            except ProcessLookupError:  # reaped already (waitpid finds none)
                pass
        for pid in adopted - spared:
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)


def exit_how(code: int) -> str:
    """How a child process ended, from its exit code as subprocess gives it (minus the
    signal that ended it): `signal SIGSEGV`, or `exit status 3`."""
    return (f"signal {signal.Signals(-code).name}" if -code in signal.valid_signals()
            else f"exit status {code}")


def pickled_error(error: BaseException) -> tuple[bytes, str]:
    """What a child process sends back of an error raised in it: the error pickled
    (empty when it cannot be), and its type and message as text, for a parent that
    cannot rebuild it (`unpickled_error`)."""
    text = f"{type(error).__name__}: {error}"
    try:
        return pickle.dumps(error), text
    except Exception:  # such as an error holding a lock
        return b"", text


def unpickled_error(data: bytes, text: str) -> BaseException:
    """The error a child process sent (`pickled_error`), or a RuntimeError naming its
    type and message where it cannot be rebuilt here (a class this process cannot
    import, an `__init__` that takes other arguments than the error keeps)."""
    if not data:
        return RuntimeError(text)
    try:
        error: BaseException = pickle.loads(data)
    except Exception as why:
        return RuntimeError(f"{text} (raised in a child process, and not rebuilt here: "
                            f"{type(why).__name__}: {why})")
    return error


# A message on the pipes of `in_own_process`: its length, then its bytes, read whole
# before they are unpickled, so that what cannot be unpickled leaves the next in place.
_LENGTH = struct.Struct("<Q")


def _send(stream: IO[bytes], message: bytes) -> None:
    stream.write(_LENGTH.pack(len(message)) + message)
    stream.flush()


def _received(stream: IO[bytes]) -> bytes | None:
    """The next message on `stream`; None at its end. EOFError when it ends mid-message."""
    head = stream.read(_LENGTH.size)
    if not head:
        return None
    if len(head) < _LENGTH.size:
        raise EOFError
    (length,) = _LENGTH.unpack(head)
    message = stream.read(length)
    if len(message) < length:
        raise EOFError
    return message


# What `in_own_process`'s child answers of a task: how it ended, the result or the error
# pickled, and the result's type, or the error's type and message (`pickled_error`).
_RETURNED, _RAISED, _UNREADABLE = "returned", "raised", "unreadable"
_Answer = tuple[str, bytes, str]


@dataclass(frozen=True, slots=True)
class _OwnProcess:
    """A process that makes a thread's tasks one after the other (`_serve`), the modules
    `preloaded` imported; the ends of its pipes of tasks and answers."""

    process: subprocess.Popen[bytes]
    preloaded: tuple[str, ...]
    tasks: IO[bytes]
    answers: IO[bytes]

    def close(self) -> None:
        with contextlib.suppress(OSError):  # a task left unsent to a process that ended
            self.tasks.close()  # which ends it, when it lives
        self.answers.close()
        self.process.wait()


_own = threading.local()  # each thread's _OwnProcess


def in_own_process(preloaded: tuple[str, ...], fn: Callable[P, T], /, *args: P.args,
                   **kwargs: P.kwargs) -> T:
    """`fn(*args, **kwargs)` in a process of this thread's own, spawned when it first
    needs one (importing the modules `preloaded` first) and kept for its next tasks, so
    that a cluster's search costs no start (some 0.5 s, bench/own_process.py);
    TaskProcessEnded when that process ends before it answers (the next task has a new
    one); TaskUnreadable when it cannot unpickle the task (it imports other code than
    this process); what the task raised, or a RuntimeError naming it where this process
    cannot rebuild it. The process ends when this one does (on Linux even amid a
    task)."""
    own: _OwnProcess | None = getattr(_own, "process", None)
    if own is None or own.preloaded != preloaded:
        if own is not None:
            own.close()
        own = _own.process = _start_own(preloaded)
    task = pickle.dumps((fn, args, kwargs))  # whole before any of it is sent
    try:
        _send(own.tasks, task)
        answer = _received(own.answers)
        if answer is None:
            raise EOFError
    except (OSError, EOFError):  # it ended, perhaps mid-answer
        _own.process = None
        own.close()
        raise TaskProcessEnded(
            f"the task's process ended ({exit_how(own.process.returncode)})") from None
    except BaseException:  # interrupted (Ctrl-C) before the answer: the next task
        # would read this one's, so the process goes with the task
        _own.process = None
        own.process.kill()
        own.close()
        raise
    how, data, text = pickle.loads(answer)
    if how == _UNREADABLE:
        raise TaskUnreadable(
            f"the process spawned for a task could not read it ({text})\n  = help: the "
            "task's code must import there as it does here: install the same rl1, and "
            "any module the task comes from, on every worker's machine, and name a "
            "module to `dask worker --preload` rather than a file")
    if how == _RAISED:
        raise unpickled_error(data, text)
    try:
        result: T = pickle.loads(data)
    except Exception as error:
        raise RuntimeError(f"the task's result, a {text}, cannot be rebuilt in this process "
                           f"({type(error).__name__}: {error})") from None
    return result


def _start_own(preloaded: tuple[str, ...]) -> _OwnProcess:
    tasks_read, tasks = os.pipe()
    answers, answers_written = os.pipe()
    try:
        process = spawn(_serve, tasks_read, answers_written, os.getpid(), preloaded,
                        keep=(tasks_read, answers_written))
    except BaseException:  # such as no process to be had (EAGAIN, ENOMEM)
        os.close(tasks)
        os.close(answers)
        raise
    finally:
        os.close(tasks_read)
        os.close(answers_written)
    return _OwnProcess(process, preloaded, open(tasks, "wb"), open(answers, "rb"))


def _serve(tasks: int, answers: int, parent: int, preloaded: tuple[str, ...]) -> None:
    """`in_own_process`'s child: for each task read from the pipe `tasks`, its answer
    (`_answer`) on the pipe `answers`, until `tasks` ends; it ends amid a task when the
    process `parent` does (`_end_with_parent`)."""
    import importlib

    _end_with_parent(parent)
    unreadable: _Answer | None = None  # every task's answer, when a preload fails
    for module in preloaded:
        try:
            importlib.import_module(module)
        except Exception as error:
            unreadable = (_UNREADABLE, b"", f"the module `{module}` the worker preloaded: "
                          f"{type(error).__name__}: {error}")
            break
    # A pipe broken: the parent ended while a task ran (its answer unwritten, this one
    # ends as the parent did).
    with contextlib.suppress(BrokenPipeError), open(tasks, "rb") as calls, \
            open(answers, "wb") as replies:
        while (task := _received(calls)) is not None:
            _send(replies, pickle.dumps(unreadable or _answer(task)))


def _answer(task: bytes) -> _Answer:
    """The pickled call `task` made: its result, or what it raised, pickled; or, when
    it cannot be unpickled here, why (a module this process does not have)."""
    try:
        fn, args, kwargs = pickle.loads(task)
    except Exception as error:
        return _UNREADABLE, b"", f"{type(error).__name__}: {error}"
    try:
        result = fn(*args, **kwargs)
    except Exception as error:  # raised again where the task was called
        return _RAISED, *pickled_error(error)
    try:
        return _RETURNED, pickle.dumps(result), type(result).__name__
    except Exception as error:  # such as a result holding a lock
        return _RAISED, *pickled_error(error)


def _end_with_parent(parent: int) -> None:
    """Has this process killed when the thread of `parent` that started it ends (Linux),
    as a Dask worker killed amid a task: the task's result would have no reader. A
    thread watching a pipe would do it anywhere, but a process of several threads
    judges apart by spawning, not forking (differential.forks_safely), ten times as
    slow. Elsewhere, this process ends at its next look for a task."""
    if _prctl(PR_SET_PDEATHSIG, signal.SIGKILL) and os.getppid() != parent:
        os._exit(128 + signal.SIGKILL)  # it ended before this process asked


def _threads(client: Client, address: str) -> int:
    """The threads of the cluster's workers now (more may join later)."""
    try:
        threads: dict[str, int] = client.nthreads()  # type: ignore[no-untyped-call]
    except OSError as error:  # the scheduler gone since it was reached (not a file
        # that could not be written, as the command line takes an OSError to be)
        raise _connection_lost(address, error) from None
    return sum(threads.values())


def _connection_lost(address: str, error: OSError) -> Unavailable:
    return Unavailable(f"the connection to the Dask scheduler at {address} was lost "
                       f"({error})")
