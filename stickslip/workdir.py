"""Where a study's results are: the workflow directory, found from any folder below it.

Snakemake writes a study's results tree ``results/{study}/`` in the directory it runs in (the one with the
``Snakefile``). :func:`stickslip.study` and ``stickslip db`` find that directory, in this order: the one
given (``workdir=``, ``--workdir``), the environment variable :data:`ENVIRONMENT`, the nearest folder at or
above the current one that holds a ``Snakefile`` (a notebook in ``notebooks/`` finds the repository's
root), else the current folder. Their messages say which one they used and why.
"""

import dataclasses
import os
from pathlib import Path

__all__ = ["ENVIRONMENT", "Workdir", "find_workdir"]

#: The environment variable naming the workflow directory.
ENVIRONMENT = "STICKSLIP_WORKDIR"


@dataclasses.dataclass(frozen=True)
class Workdir:
    """A workflow directory and how it was found.

    Attributes
    ----------
    path : pathlib.Path
    how : str
        Why this one, for messages (e.g. "the nearest folder above /x/notebooks with a Snakefile").
    """

    path: Path
    how: str

    def __str__(self):
        return f"{self.path.resolve()} ({self.how})"


def find_workdir(given=None, start=None):
    """The workflow directory (module docstring).

    Parameters
    ----------
    given : str or os.PathLike, optional
        A directory given by the caller; it wins.
    start : str or os.PathLike, optional
        Where the search upwards starts (default: the current directory).

    Returns
    -------
    Workdir
    """
    if given is not None:
        return Workdir(Path(given).expanduser(), "given")
    if os.environ.get(ENVIRONMENT):
        return Workdir(Path(os.environ[ENVIRONMENT]).expanduser(), f"${ENVIRONMENT}")
    here = Path.cwd()
    start = here if start is None else Path(start).resolve()
    for folder in (start, *start.parents):
        if (folder / "Snakefile").is_file():
            how = ("the current folder, which holds the Snakefile" if folder == start else
                   f"the nearest folder above {start} with a Snakefile")
            return Workdir(Path() if folder == here else folder, how)  # the current folder: paths stay relative
    return Workdir(Path() if start == here else start, "the current folder: no folder at or above it holds a Snakefile")
