"""Lineage: what a job reads, passed to it by the study (never parsed back from paths).

An :class:`Artifact` is one file with the identity of the job that made it: its run id,
the producing plugin and the file's format, and, for an analysis output, the simulation
it was made from (``parent``). The study builds them, the rules hand them to the jobs as
JSON, the jobs record them in provenance, and the database ingests them. An artifact is
path-like (``os.fspath``), so readers that take a path take an artifact too.
"""

import dataclasses
import os
from pathlib import Path

__all__ = ["Artifact"]


@dataclasses.dataclass(frozen=True)
class Artifact:
    """One file passed between stages, with its lineage.

    Attributes
    ----------
    path : pathlib.Path
    run_id : str
        Id of the job that wrote it (a mesh: its mesh id).
    plugin : str
        The producing plugin (``"mesh"`` for meshes).
    format : str
        Its format (:mod:`stickslip.formats`).
    parent : Artifact or None
        The simulation an analysis output was made from.
    """

    path: Path
    run_id: str
    plugin: str
    format: str
    parent: "Artifact | None" = None

    def __post_init__(self):
        object.__setattr__(self, "path", Path(self.path))

    def __fspath__(self):
        return os.fspath(self.path)

    def __str__(self):
        return self.path.as_posix()

    def to_dict(self):
        """Return the artifact as a JSON-able dict (``parent`` nested)."""
        return {"path": self.path.as_posix(), "run_id": self.run_id, "plugin": self.plugin, "format": self.format,
                "parent": None if self.parent is None else self.parent.to_dict()}

    @classmethod
    def from_dict(cls, values):
        """Inverse of :meth:`to_dict`."""
        parent = values.get("parent")
        return cls(Path(values["path"]), values["run_id"], values["plugin"], values["format"],
                   None if parent is None else cls.from_dict(parent))

    def files(self):
        """Return this file and its ancestors' files, nearest first."""
        return [self.path] + ([] if self.parent is None else self.parent.files())
