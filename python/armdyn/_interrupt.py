"""Ctrl-C while the ``armdyn`` command is still starting.

``python -m armdyn ...`` (and the ``armdyn`` script) imports the package, and with it
SymPy, for about a second before :func:`armdyn.cli.main` runs; a Ctrl-C in that second
used to end in a Python traceback from somewhere inside SymPy's import. When this
process is the command, the package's first lines call :func:`quiet_until_main`: until
``main`` calls :func:`raise_from_now_on`, SIGINT prints the command's usual
``armdyn: interrupted`` line and exits with status 130. Nothing has been written yet
then, so there is nothing to clean up. Imported as a library, nothing changes.
"""

from __future__ import annotations

import os
import signal
import sys
import threading

#: the line the command prints on Ctrl-C (also armdyn.cli.main's)
INTERRUPTED = "armdyn: interrupted\n"


def _is_the_command() -> bool:
    """True while ``python -m armdyn`` imports the package (runpy sets ``sys.argv[0]``
    to ``-m`` until the package is found) or when run as the ``armdyn`` script."""
    argv = sys.argv or [""]
    if argv[0] == "-m":
        orig = list(getattr(sys, "orig_argv", []))
        return any(a == "-m" and b == "armdyn" or a == "-marmdyn" for a, b in zip(orig, orig[1:] + [""]))
    return os.path.basename(argv[0]) == "armdyn"


def _exit_interrupted(signum, frame):
    os.write(2, INTERRUPTED.encode())
    os._exit(130)  # no interpreter shutdown: an import is half-done, and nothing to flush


def quiet_until_main() -> None:
    """Install the quiet SIGINT handler if this process is the command and Ctrl-C still
    has Python's default meaning (not ignored, nobody else's handler)."""
    if (
        _is_the_command()
        and threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    ):
        signal.signal(signal.SIGINT, _exit_interrupted)


def raise_from_now_on() -> None:
    """Back to Python's KeyboardInterrupt (which ``main`` turns into the same line, after
    the temporary files of half-written outputs are removed)."""
    if signal.getsignal(signal.SIGINT) is _exit_interrupted:
        signal.signal(signal.SIGINT, signal.default_int_handler)
