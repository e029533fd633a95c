"""The ``frictionlab`` command. Each subcommand lives in ``frictionlab/commands/<name>.py`` and
exposes ``add_parser(subparsers)`` (which sets ``func``) and its run function; it builds its parser
with ``subcommand(sub, name, help, description, examples)`` so that every subcommand accepts the
global options and shows its examples.

One grammar: global options (--load, --debug, --quiet) go before or after the subcommand; a list
is given by repeating an option or with commas (``ListAction``); errors are one line on stderr and
exit status 2; ``--debug`` shows the traceback.
"""
from __future__ import annotations

import argparse
import importlib
import sys
import warnings

from .core.errors import FrictionLabError, Terminated

COMMANDS = ("laws", "datasets", "simulate", "fit", "compare", "bench", "record", "healing")


LISTS_HELP = ("Lists: repeat an option or separate values with commas; both work everywhere "
              "(--laws wear,coulomb is --laws wear --laws coulomb).")


class ListAction(argparse.Action):
    """A list option: repeatable, and each value may hold several items separated by commas."""

    def __call__(self, parser, namespace, values, option_string=None):
        items = list(getattr(namespace, self.dest, None) or [])
        for v in values if isinstance(values, list) else [values]:
            parts = [x.strip() for x in v.split(",")]
            if not all(parts):  # '--laws ,' must not mean the default set
                parser.error(f"argument {option_string}: {v!r} holds an empty name; give names separated by commas")
            items += parts
        setattr(namespace, self.dest, items)


def add_globals(parser, top: bool) -> None:
    """--load, --debug and --quiet; on a subcommand they go to separate names merged in main()."""
    pre = "" if top else "sub_"
    kw = {} if top else {"default": argparse.SUPPRESS}
    parser.add_argument("--debug", dest=pre + "debug", action="store_true", help="show tracebacks on errors", **kw)
    parser.add_argument("--quiet", "-q", dest=pre + "quiet", action="store_true",
                        help="no progress output (results and errors are still printed)", **kw)
    parser.add_argument("--load", dest=pre + "load", metavar="FILE.py", action=ListAction,
                        help="import a Python file first (laws it registers with @register_law become "
                             "available); repeatable", **({"default": []} if top else kw))


def subcommand(sub, name: str, help: str, description: str, examples: str = ""):
    """A subcommand parser with the global options and an 'examples' epilog."""
    import textwrap

    p = sub.add_parser(name, help=help, description=textwrap.fill(description, 88),
                       epilog=("examples:\n" + examples.rstrip() + "\n\n" if examples else "") + LISTS_HELP,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    add_globals(p, top=False)
    return p


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line usage error (no usage block), exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see '{self.prog} --help')\n")


def one_line(text) -> str:
    """A message on one line: newlines inside (a file name, a column name) become spaces."""
    return " ".join(str(text).split("\n")).replace("\r", " ")


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = _Parser(prog="frictionlab", description="Compare friction laws against impact and sliding data.",
                     epilog="Global options go before or after the command. " + LISTS_HELP
                     + " 'frictionlab COMMAND --help' shows a command's options and examples.")
    parser.add_argument("--version", action="version", version=f"frictionlab {__version__}")
    add_globals(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"frictionlab.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"frictionlab.commands.{name}":
                continue  # not built yet
            raise
        module.add_parser(sub)
    return parser




def load_file(path: str) -> None:
    """Import a user's Python file by path (for laws registered at run time)."""
    from .physics.registry import load_law_file

    load_law_file(path)


def main(argv=None) -> int:
    """Run the command line ``argv``; the exit status: 0 done, 2 bad input or a refused output, 1 a bug,
    130/143/129 interrupted, terminated or hung up, 141 the reader of the output went away."""
    from .core.terminal import guarded_streams

    argv = sys.argv[1:] if argv is None else list(argv)
    with guarded_streams() as (out, err):  # all output inert and encodable; a failing stream named
        try:
            rc = _main(argv)
        except (KeyboardInterrupt, Terminated) as exc:  # a signal while the run's ending was being said
            rc = 128 + int(getattr(exc, "signum", 2))
            _say_quietly("interrupted" if rc == 130 else exc.word())
        out.flush()
        if out.failure is not None and rc != 141:
            print(f"frictionlab: error: cannot write to {out.name}: {out.failure.strerror or out.failure} "
                  "(files the run wrote are complete)", file=sys.stderr)
            rc = rc or 2
        return rc


def _main(argv: list[str]) -> int:
    try:
        parser = build_parser()
    except Exception as exc:  # a command module that fails to import
        if "--debug" in argv:
            raise
        return _say(f"internal error: {type(exc).__name__}: {one_line(exc)} (rerun with --debug for the traceback)", 1)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse already printed its one-line usage error
        return int(exc.code or 0) if exc.code in (0, None) else 2
    args.load = list(args.load) + list(getattr(args, "sub_load", []))
    args.debug = args.debug or getattr(args, "sub_debug", False)
    args.quiet = args.quiet or getattr(args, "sub_quiet", False)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    return _run(args)


def _say_quietly(message: str) -> None:
    try:
        print(f"frictionlab: {message}", file=sys.stderr)
    except (Exception, KeyboardInterrupt, Terminated):  # noqa: BLE001 (nothing more can be said)
        pass


def _warn_quietly(message: str) -> None:
    try:
        print(f"warning: {message}", file=sys.stderr)
    except (Exception, KeyboardInterrupt, Terminated):  # noqa: BLE001 (nothing more can be said)
        pass


def _say(message: str, status: int) -> int:
    print(f"frictionlab: {message}", file=sys.stderr)
    return status


def _run(args) -> int:
    """Run the parsed command; every way it can end becomes one line on stderr and an exit status."""
    from .core.fpstate import own_errstate
    from .core.inputs import inputs_of_run

    formatwarning = warnings.formatwarning
    restore = _signals_end_cleanly()
    try:
        with warnings.catch_warnings(), inputs_of_run():  # outputs keep clear of every file the run reads
            warnings.simplefilter("default")
            warnings.simplefilter("ignore", ResourceWarning)  # e.g. an import cut short by a signal: not the user's
            warnings.formatwarning = lambda m, c, *a, **k: f"warning: {one_line(m)}\n"
            pin_paths(args)  # before any plugin runs: one that changes the working folder moves nothing
            with own_errstate():  # numpy's error state of its own, whatever a plugin sets at import
                for path in args.load:
                    load_file(path)
                return int(args.func(args) or 0)
    except FrictionLabError as exc:
        if args.debug:
            raise
        return _say(f"error: {one_line(exc)}", 2)
    except BrokenPipeError:  # the reader of our output went away (| head): stop quietly, as cat does
        _silence_stdout()
        return 141
    except OSError as exc:  # the file system refused (permissions, a full disk): the user's to fix
        if args.debug:
            raise
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else _cwd_gone()
        return _say(f"error: {where}{one_line(exc.strerror or exc)}", 2)
    except KeyboardInterrupt:
        return _say("interrupted", 130)
    except Terminated as exc:
        return _say(exc.word(), 128 + exc.signum)
    except Exception as exc:  # a bug, not bad input: say so in one line, exit 1
        if args.debug:
            raise
        return _say(f"internal error: {type(exc).__name__}: {one_line(exc)} "
                    "(a bug in frictionlab or a plugin; rerun with --debug for the traceback)", 1)
    finally:
        warnings.formatwarning = formatwarning
        restore()


#: The options and arguments that name files or folders (a dataset argument only when it is a path).
PATH_ARGS = ("out", "json", "plot", "raw", "load", "data", "datasets", "dataset", "name")


def pin_paths(args) -> None:
    """Make every path the command line names absolute against the folder the run starts in, spelled as given
    ('sub/../d.csv' stays so, below that folder): a plugin that changes the working folder at import or in a call
    cannot move the run's inputs or outputs. A dataset argument is a path when it ends in .toml or .csv or holds a
    '/'; otherwise it is a built-in name."""
    import os
    from pathlib import Path

    try:
        here = os.getcwd()
    except OSError:  # the folder was deleted: relative paths fail later, each naming itself
        return

    def pinned(v):
        if isinstance(v, Path):
            return v if v.is_absolute() else Path(here) / v
        if isinstance(v, str) and v and not os.path.isabs(v) and (os.sep in v or v.endswith((".toml", ".csv", ".py"))):
            return os.path.join(here, v)
        return v

    for key in PATH_ARGS:
        if key == "name" and getattr(args, "action", None) != "show":  # elsewhere --name is a name
            continue
        value = getattr(args, key, None)
        if isinstance(value, list):
            setattr(args, key, [pinned(v) for v in value])
        elif value is not None:
            setattr(args, key, pinned(value))


#: The BLAS thread pools the command line runs with one thread, unless the environment sets them: its linear algebra
#: is many small products on one record at a time, where waking a pool's threads costs more than it saves (on a
#: 2-core virtual machine a 31,000-sample Ljung-Box test took 0.16 CPU s with OpenBLAS's threads and 0.4 ms
#: without), and ``--jobs`` runs processes, whose pools would compete for the same cores.
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")


def blas_one_thread() -> None:
    """Each of BLAS_THREADS that the environment leaves unset, set to 1 (read when numpy is first imported, and
    inherited by worker processes)."""
    import os

    for name in BLAS_THREADS:
        os.environ.setdefault(name, "1")


def entry() -> None:
    """The ``frictionlab`` console script (and ``python -m frictionlab``): ``main()`` with one BLAS thread
    (``blas_one_thread``), then the process ends as soon as its work is done. What it wrote is flushed; a thread
    a plugin started (not a daemon) does not hold it, nor do child processes a plugin forked and left running
    (they are ended, so that they hold neither the process nor its output streams), each named in a warning."""
    blas_one_thread()
    rc = main()
    end_process(rc)


def end_process(rc: int) -> None:
    import os
    import threading

    threads = [t for t in threading.enumerate()
               if t is not threading.main_thread() and not t.daemon and t.is_alive()]
    children = _children()
    for pid in children:
        try:
            os.kill(pid, 9)  # SIGKILL: a plugin's helper left behind
        except OSError:
            pass
    if threads or children:
        left = [f"thread {t.name!r}" for t in threads] + [f"process {pid}" for pid in children]
        _warn_quietly(f"code loaded in this run left {', '.join(left)} running; not waiting for "
                     f"{'it' if len(left) == 1 else 'them'}" + ("" if not children else " (the processes were ended)"))
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001 (a closed or broken stream: nothing more can be said)
            pass
    if threads or children or rc in SIGNALLED:
        os._exit(rc)
    sys.exit(rc)


#: The exit statuses of a run ended by SIGHUP, SIGINT or SIGTERM (128 + the signal's number). Such a run has
#: already removed its temporary output, released its locks and stopped its workers when ``end_process`` is
#: called, so it ends there and then: CPython remembers a ^C that interrupted code run by ``exec`` of a string
#: (a dataclass or namedtuple being made, a compiler's generated code) even when frictionlab caught it, and
#: would then end the process by SIGINT at exit instead of with status 130.
SIGNALLED = (129, 130, 143)


def _children() -> list[int]:
    """The process ids of this process's children still running (Linux /proc; [] elsewhere)."""
    import os

    me, found = os.getpid(), []
    try:
        names = os.listdir("/proc")
    except OSError:
        return []
    for name in names:
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                fields = f.read().rsplit(b")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if len(fields) > 2 and int(fields[1]) == me and fields[0] != b"Z":
            found.append(int(name))
    return found


def _cwd_gone() -> str:
    """What to say before an OSError that names no file: that the current folder was deleted, if it was."""
    import os

    try:
        os.getcwd()
    except OSError:
        return "the current folder no longer exists (deleted while in use; cd to an existing folder): "
    return ""


def _silence_stdout() -> None:
    try:
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def _signals_end_cleanly():
    """Make SIGTERM and SIGHUP an exception (errors.Terminated), and SIGINT KeyboardInterrupt, while a command
    runs, so that clean-up runs: workers stopped, temporary output removed, locks released; if the exception
    is swallowed (a plugin's bare except, a finalizer), the run ends HARD_EXIT_AFTER seconds later all the
    same. A forked child signalled before it set its own handlers just ends. Returns the function that
    undoes it."""
    import os
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    me = os.getpid()

    def on_signal(signum, frame):
        if os.getpid() != me:  # a forked worker signalled before it set its own handlers: it just ends
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        if not caught:  # a plugin's bare except: may swallow the exception: then end anyway, cleanly
            timer = threading.Timer(HARD_EXIT_AFTER, _hard_exit, (signum,))
            timer.daemon = True
            timer.start()
            caught.append(timer)
        else:
            _hard_exit(signum)
        raise KeyboardInterrupt if signum == signal.SIGINT else Terminated(signum)

    def unraisable(u):  # a signal's exception raised in a finalizer, where Python only prints it: end now
        if isinstance(u.exc_value, (Terminated, KeyboardInterrupt)) and os.getpid() == me:
            _hard_exit(getattr(u.exc_value, "signum", signal.SIGINT))
        hook(u)

    caught = []
    sigs = [getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)]
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:  # ^C ignored by whoever started us
        sigs.remove(signal.SIGINT)
    old = {s: signal.signal(s, on_signal) for s in sigs}
    hook, sys.unraisablehook = sys.unraisablehook, unraisable

    def restore():
        for t in caught:
            t.cancel()
        for s, h in old.items():
            signal.signal(s, h)
        sys.unraisablehook = hook
    return restore


#: Seconds after SIGINT, SIGTERM or SIGHUP before the process ends even if the exception raised was swallowed.
HARD_EXIT_AFTER = 3.0


def _hard_exit(signum: int) -> None:
    """End now: temporary output and locks removed, one line said; workers end with us (PDEATHSIG)."""
    import os

    from .core.errors import Terminated
    from .core.files import remove_leftovers

    remove_leftovers()
    try:
        word = "interrupted" if signum == 2 else Terminated(signum).word()  # 2: SIGINT
        sys.stderr.write(f"frictionlab: {word}\n")
        sys.stderr.flush()
    except Exception:  # noqa: BLE001 (nothing more can be said)
        pass
    os._exit(128 + int(signum))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
