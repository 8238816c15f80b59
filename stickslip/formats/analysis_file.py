"""The one header of every analysis output: format, analysis identity, parameters, input checksum.

Root attributes written by :func:`write_analysis_file`, whatever the format:

``format``, ``format_version``
    The output's format (:mod:`stickslip.formats`).
``analysis``, ``analysis_version``
    The analysis plugin that wrote it.
``analysis_params``
    Its parameters, canonical JSON.
``input_sha256``
    sha256 of the analysed file.

Before them, the analysis may copy attributes of its input (the run's ``N``, ``n``,
``seed``, ...), so that figures group runs by what the files say about themselves;
the header's names win over copied ones.
"""

from .. import h5io
from ..hashing import canonical_json, sha256_file
from ..output_safety.atomic import atomic_output
from ..plugin_params import params_to_dict
from . import check, stamp

__all__ = ["HEADER", "write_analysis_file", "open_analysis_file"]

#: Root attributes of the header.
HEADER = ("format", "format_version", "analysis", "analysis_version", "analysis_params", "input_sha256")


def write_analysis_file(output, fmt, *, analysis, version, params, input, attrs, tables):
    """Write an analysis output (atomically): copied attributes, the header, the tables.

    Parameters
    ----------
    output : str or os.PathLike
    fmt : str
        Format of the output.
    analysis, version : str
        Name and version of the analysis plugin.
    params : object
        Its parameter dataclass instance.
    input : str or os.PathLike
        The analysed file (its checksum goes into the header).
    attrs : Mapping[str, object]
        Further root attributes (e.g. the run's), see :func:`stickslip.h5io.write_attrs`.
    tables : Mapping[str, pandas.DataFrame]
        Tables by name (:func:`stickslip.h5io.write_table`).
    """
    header = {"analysis": analysis, "analysis_version": version,
              "analysis_params": canonical_json(params_to_dict(params)), "input_sha256": sha256_file(input)}
    with atomic_output(output) as tmp, h5io.open_file(tmp, "w") as file:
        h5io.write_attrs(file, {key: value for key, value in attrs.items() if key not in HEADER})
        h5io.write_attrs(file, header)
        stamp(file, fmt)
        for name, table in tables.items():
            h5io.write_table(file, name, table)


def open_analysis_file(path, fmt):
    """Open an analysis output for reading, checking its format and version.

    Parameters
    ----------
    path : str or os.PathLike
    fmt : str

    Returns
    -------
    h5py.File

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is unreadable or of another format or version.
    """
    file = h5io.open_file(path)
    try:
        check(file, fmt)
    except BaseException:
        with file:  # closed; a failure of HDF5 becomes a CorruptFileError naming the file (h5io.open_file)
            raise
    return file
