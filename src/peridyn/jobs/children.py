"""Helper processes (the figure worker, a sweep's pool workers) end with the process that
started them, whatever ended it: a SIGKILL or an out-of-memory kill leaves the parent no
chance to shut them down. On Linux the kernel sends the child SIGKILL when its parent dies
(``prctl(PR_SET_PDEATHSIG)``); elsewhere a thread of the child watches its parent and ends it.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time

#: Seconds between two looks at the parent by the watching thread (where prctl is missing).
WATCH_S = 0.5

#: Linux's ``PR_SET_PDEATHSIG`` (``<sys/prctl.h>``).
PR_SET_PDEATHSIG = 1


def end_with_parent(parent: int) -> None:
    """End this process when the process ``parent`` (its parent's id, given by the parent)
    ends; to be called first thing in the child (a pool's initializer)."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
            if os.getppid() != parent:  # the parent died before the prctl
                os._exit(1)
            return

    def watch():
        while os.getppid() == parent:
            time.sleep(WATCH_S)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="parent-watch").start()
