"""What memory this process can have: the machine's, its limits (``ulimit -v``, ``ulimit -d``), what is left.

A reader budgets a read against what the process can still allocate (:func:`stickslip.h5io.read_budget`); a solver
refuses parameters whose run would need more than the machine has (:func:`process_memory`), as a writer refuses to
start on a disk without room (:func:`stickslip.output_safety.space.check_free_space`).
"""

import math
import resource

__all__ = ["meminfo", "process_memory", "resident_memory", "room_left", "size_text"]


def meminfo(field):
    """A field of /proc/meminfo [B] (None where there is none)."""
    return _proc_field("/proc/meminfo", field)


def _own(field):
    """A field of /proc/self/status [B] (0 where there is none)."""
    return _proc_field("/proc/self/status", field) or 0


def _proc_field(path, field):
    try:
        with open(path, encoding="ascii") as lines:
            for line in lines:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _limits():
    """``(soft limit, /proc/self/status field of its use)`` of the address space and the data segment that are set."""
    found = []
    for limit, used in ((resource.RLIMIT_AS, "VmSize"), (resource.RLIMIT_DATA, "VmData")):
        soft = resource.getrlimit(limit)[0]
        if soft != resource.RLIM_INFINITY:
            found.append((soft, used))
    return found


def resident_memory():
    """What this process holds in memory now (``VmRSS``) [B]; 0 where nothing says."""
    return _own("VmRSS")


def room_left():
    """What this process can still allocate [B]: the least of the memory available (``MemAvailable``) and the room
    left under its address-space and data limits; ``inf`` where nothing says."""
    room = [meminfo("MemAvailable")] + [max(0, soft - _own(used)) for soft, used in _limits()]
    return min((r for r in room if r is not None), default=math.inf)


def process_memory():
    """The most memory a process of this machine can have [B]: the least of the machine's memory (``MemTotal``) and
    this process's address-space and data limits; ``inf`` where nothing says."""
    sizes = [meminfo("MemTotal")] + [soft for soft, _ in _limits()]
    return min((s for s in sizes if s is not None), default=math.inf)


def size_text(nbytes):
    """``nbytes`` as a short text (B, KiB, MiB, GiB, TiB)."""
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes:.0f} B"
