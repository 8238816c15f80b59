"""SI figure: fraction of slip events that are part of a sequence of single- or multi-slips.

A sequence is two or more consecutive slip events of the same kind (microscopic events in
between do not count). Against the number of interfaces n: the fraction of events in any
sequence (squares) and in sequences of single slips (circles); the band between them is the
fraction in multi-slip sequences. (a) stiff, (b) compliant driving; runs pooled over seeds.
"""

import dataclasses

import numpy as np

from ..events.extraction import sequence_fractions
from ..events.analysis_files import group_runs, pooled
from ..registry import register
from .numerical_common import REGIME_LABEL, read_inputs
from .plotting import label_panels
from .style import plt, save_figure

__all__ = ["SequencesParams", "fractions_by_n", "run"]

NAME = "figS-sequences"

#: Colours of the paper's figure: single-slip sequences red, all sequences blue.
SINGLE_COLOR, ANY_COLOR = "#d7301f", "#2c7fb8"


@dataclasses.dataclass(frozen=True)
class SequencesParams:
    """The sequences figure has no parameter."""


def fractions_by_n(groups, regime):
    """Sequence fractions per number of interfaces for one driving regime.

    Parameters
    ----------
    groups : dict[tuple[str, int], list[AnalysisFile]]
        Output of :func:`stickslip.events.analysis_files.group_runs` (files with table ``sequences``).
    regime : str

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray, numpy.ndarray]
        n [k], fraction in single-slip sequences [k], fraction in any sequence [k] (runs
        without slip events left out).
    """
    rows = []
    for (group_regime, n), files in groups.items():
        sequences = pooled(files, "sequences")
        if group_regime == regime and not sequences.empty:
            fractions = sequence_fractions(sequences)
            rows.append((n, fractions["single"], fractions["any"]))
    n, single, any_ = (np.array(column, dtype=float) for column in zip(*rows)) if rows else (np.zeros(0),) * 3
    return n, single, any_


@register("figure", NAME, "1", SequencesParams, inputs=("analysis:numerical-events",))
def run(params, inputs, output):
    """SI: fraction of slip events in single- or multi-slip sequences against n, stiff and compliant."""
    groups = group_runs(read_inputs(inputs, "analysis:numerical-events", ("sequences",), NAME))
    fig, axes = plt.subplots(1, 2, figsize=(7.0, 2.8), constrained_layout=True, sharey=True)
    for ax, regime in zip(axes, ("stiff", "compliant")):
        n, single, any_ = fractions_by_n(groups, regime)
        ax.fill_between(n, 0, single, color=SINGLE_COLOR, alpha=0.2, lw=0)
        ax.fill_between(n, single, any_, color=ANY_COLOR, alpha=0.25, lw=0, label="in multi-slip sequences")
        ax.plot(n, any_, "s-", color=ANY_COLOR, label="in any sequence")
        ax.plot(n, single, "o-", color=SINGLE_COLOR, label="in single-slip sequences")
        ax.set_xlabel("$n$")
        ax.set_ylim(0, 1.02)
        ax.xaxis.get_major_locator().set_params(integer=True)
        ax.set_title(REGIME_LABEL[regime], fontsize=9)
    label_panels(axes)
    axes[0].set_ylabel("fraction of slip events")
    axes[1].legend(fontsize=7, frameon=False, loc="lower left")
    save_figure(fig, output)
