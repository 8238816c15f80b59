"""Helpers shared by the figures of the numerical study (fig2, figS-dgamma, figS-sequences,
figS-event-maps, figS-tau): reading their inputs, line styles per driving regime.
"""

from ..events.results import read_analysis_file
from ..h5io import FileFormatError

__all__ = ["REGIME_LINESTYLE", "REGIME_LABEL", "read_inputs"]

#: The paper's convention: stiff driving dashed, compliant solid.
REGIME_LINESTYLE = {"stiff": "--", "compliant": "-"}

REGIME_LABEL = {"stiff": "stiff driving", "compliant": "compliant driving"}


def read_inputs(inputs, category, tables, figure):
    """Read every analysis file of one input category.

    Parameters
    ----------
    inputs : Mapping[str, Sequence[str or pathlib.Path]]
        The figure's inputs, by category.
    category : str
        E.g. ``"analysis:numerical-events"``.
    tables : tuple[str, ...]
        Tables to read from each file.
    figure : str
        Figure name, for error messages.

    Returns
    -------
    list[stickslip.events.results.AnalysisFile]

    Raises
    ------
    FileFormatError
        If the category has no file.
    """
    paths = list(inputs.get(category, []))
    if not paths:
        raise FileFormatError(f"figure '{figure}': no input file of category '{category}'")
    return [read_analysis_file(path, tables) for path in paths]
