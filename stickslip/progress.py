"""Progress of long work: a live bar on a terminal, one line per interval in a log.

Every long loop of the package (the ``fem`` increment loop, the virtual experiment,
analyses over many runs or events, ingest) reports through :func:`bar` or
:func:`iterate` (tqdm underneath), always from Python code, never from inside a
jitted kernel. Where the progress goes:

- a terminal (the stream is a TTY): tqdm's live bar, refreshed several times a second;
- a Jupyter notebook (the stream is the kernel's output of the cell): a live bar too, tqdm's widget
  where ipywidgets is installed (:mod:`tqdm.autonotebook`), else the terminal's bar, which the notebook
  redraws in place;
- anything else (a Snakemake job's log, ``2> run.log``, a SLURM output file): one
  complete line every :func:`log_interval` seconds (default 10 s, environment
  variable ``STICKSLIP_PROGRESS_INTERVAL``) and a last line when the work ends,
  instead of a bar redrawn with carriage returns.

A log line reads e.g. ``fem increments: 412/1000 increment (41%) [00:40 elapsed, 00:57 left, 10.20 increment/s,
slips 37]``: done/total, elapsed and time left (when the total is known), rate, and what the caller
adds (:meth:`tqdm.tqdm.set_postfix_str`).
"""

import os
import sys
import warnings

from tqdm import TqdmWarning, tqdm

# tqdm's widget bar in a Jupyter kernel where ipywidgets is installed, its terminal bar elsewhere (which a
# notebook redraws in place too); without tqdm's notices ("notebook mode", "IProgress not found") and
# tqdm.auto's import of asyncio (30 ms).
with warnings.catch_warnings():
    warnings.simplefilter("ignore", TqdmWarning)
    from tqdm.autonotebook import tqdm as notebook_tqdm

__all__ = ["INTERVAL_VARIABLE", "DEFAULT_LOG_INTERVAL", "log_interval", "bar", "iterate"]

#: Environment variable: seconds between two progress lines in a log.
INTERVAL_VARIABLE = "STICKSLIP_PROGRESS_INTERVAL"

#: Seconds between two progress lines in a log, unless the variable says otherwise.
DEFAULT_LOG_INTERVAL = 10.0


#: Log line formats without and with a known total (tqdm ``bar_format``; the unit starts with a space).
_LOG_FORMAT = {
    False: "{desc}: {n_fmt}{unit} [{elapsed} elapsed, {rate_noinv_fmt}{postfix}]",
    True: "{desc}: {n_fmt}/{total_fmt}{unit} ({percentage:.0f}%) [{elapsed} elapsed, {remaining} left, "
          "{rate_noinv_fmt}{postfix}]",
}


class _Lines:
    """A stream that receives tqdm's carriage-return redraws as whole lines (for logs).

    A line equal to the one before is not written again (tqdm draws the last state once more on
    closing: after an error at the start, that was the first line twice).
    """

    def __init__(self, stream):
        self.stream = stream
        self.last = None

    def write(self, text):
        text = text.replace("\r", "").rstrip()
        if text and text != self.last:
            self.stream.write(text + "\n")
            self.last = text

    def flush(self):
        self.stream.flush()


def log_interval():
    """Return the seconds between two progress lines in a log.

    Returns
    -------
    float
        ``$STICKSLIP_PROGRESS_INTERVAL`` if set, else :data:`DEFAULT_LOG_INTERVAL`.

    Raises
    ------
    ValueError
        If the variable is not a number > 0; the message names the variable.
    """
    value = os.environ.get(INTERVAL_VARIABLE, "")
    if not value:
        return DEFAULT_LOG_INTERVAL
    try:
        seconds = float(value)
    except ValueError:
        seconds = float("nan")
    if not seconds > 0:
        raise ValueError(f"environment variable {INTERVAL_VARIABLE}: expected a number of seconds > 0, got {value!r}")
    return seconds


def _is_terminal(stream):
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


def _is_notebook(stream):
    """Whether ``stream`` is a Jupyter kernel's output stream (a notebook cell's stdout or stderr)."""
    return type(stream).__module__.startswith("ipykernel.")


def bar(total=None, *, desc, unit="it", initial=0, postfix=None, stream=None):
    """Return a progress bar for the current stream (use it as a context manager).

    Parameters
    ----------
    total : int or float, optional
        Amount of work (e.g. increments, seconds of simulated time); None when unknown
        (then no time left is shown).
    desc : str
        What is counted, first on the line.
    unit : str, optional
        Unit of the count; the rate is shown in ``unit/s``.
    initial : int or float, optional
        Work already done (a resumed run).
    postfix : str, optional
        Shown at the end of the line from the first line on (later:
        ``set_postfix_str(text, refresh=False)``).
    stream : file-like, optional
        Where progress goes; default: ``sys.stderr`` at the time of the call (a job's
        log when the workflow redirected it).

    Returns
    -------
    tqdm.tqdm
        Call ``update(amount)`` as work is done.
    """
    stream = sys.stderr if stream is None else stream
    if _is_terminal(stream) or _is_notebook(stream):  # the unit after a space: "149 increment", "2.30 increment/s"
        live = tqdm if _is_terminal(stream) else notebook_tqdm
        return live(total=total, desc=desc, unit=f" {unit}", initial=initial, postfix=postfix, file=stream,
                    dynamic_ncols=True)
    interval = log_interval()
    # miniters=1: every update checks the clock, so the interval holds however the rate changes.
    return tqdm(total=total, desc=desc, unit=f" {unit}", initial=initial, postfix=postfix, file=_Lines(stream),
                mininterval=interval, maxinterval=interval, miniters=1, bar_format=_LOG_FORMAT[total is not None])


def iterate(items, *, desc, unit="it", stream=None):
    """Iterate over ``items`` with progress (see :func:`bar`).

    Parameters
    ----------
    items : Iterable
        Its ``len()`` is the total when it has one.
    desc, unit, stream
        See :func:`bar`.

    Yields
    ------
    object
        The items, in order.
    """
    total = len(items) if hasattr(items, "__len__") else None
    with bar(total, desc=desc, unit=unit, stream=stream) as progress:
        for item in items:
            yield item
            progress.update(1)
