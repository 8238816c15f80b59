"""Helpers shared by the figures of the numerical study (fig2, figS-dgamma, figS-sequences,
figS-event-maps, figS-tau): reading their inputs, line styles per driving regime.
"""

from ..events.analysis_files import read_analysis_file
from ..fem.stiffness import at_paper_phi
from ..formats import event_table, front_table
from ..h5io import FileFormatError

__all__ = ["REGIME_LINESTYLE", "REGIME_LABEL", "INPUT_FORMATS", "read_inputs", "run_phi"]

#: The format of each input category of the numerical figures.
INPUT_FORMATS = {"analysis:numerical-events": event_table.FORMAT, "analysis:front-dynamics": front_table.FORMAT}

#: The paper's convention: stiff driving dashed, compliant solid.
REGIME_LINESTYLE = {"stiff": "--", "compliant": "-"}

REGIME_LABEL = {"stiff": r"stiff driving, $\Phi \simeq 5 \times 10^{-4}$",
                "compliant": r"compliant driving, $\Phi \simeq 5 \times 10^{-7}$"}


def run_phi(attrs):
    """Phi of the run an analysis file comes from: its ``phi`` attribute, as the run file states it (float)."""
    return float(attrs["phi"])


def read_inputs(inputs, category, tables, figure, paper_phi=True):
    """Read the analysis files of one input category (by default those of runs at the paper's Phi).

    Parameters
    ----------
    inputs : Mapping[str, Sequence[str or pathlib.Path]]
        The figure's inputs, by category.
    category : str
        A key of :data:`INPUT_FORMATS`, e.g. ``"analysis:numerical-events"``.
    tables : tuple[str, ...]
        Tables to read from each file.
    figure : str
        Figure name, for error messages.
    paper_phi : bool, optional
        Keep only runs at the paper's Phi, 5e-4 (stiff) or 5e-7 (compliant) within a factor
        sqrt(10) (:func:`stickslip.fem.stiffness.at_paper_phi`): the figures of the paper
        leave out the runs of a Phi sweep.

    Returns
    -------
    list[stickslip.events.analysis_files.AnalysisFile]

    Raises
    ------
    FileFormatError
        If the category has no file (at the paper's Phi), or a file is not of the category's format.
    """
    paths = list(inputs.get(category, []))
    if not paths:
        raise FileFormatError(f"figure '{figure}': no input file of category '{category}'")
    files = [read_analysis_file(path, INPUT_FORMATS[category], tables) for path in paths]
    if paper_phi:
        files = [item for item in files if at_paper_phi(run_phi(item.attrs))]
        if not files:
            raise FileFormatError(f"figure '{figure}': no input of category '{category}' from a run at the paper's "
                                  f"Phi (5e-4 or 5e-7 within a factor 3.2; docs/numerical-analysis.md)")
    return files
