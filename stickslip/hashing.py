"""The package's two hashes: of a file's bytes, and of a JSON-able value (ids of runs, meshes, jobs).

Every id and checksum in the package comes from here, so equal inputs give equal ids
wherever they are computed.
"""

import hashlib
import json

__all__ = ["sha256_file", "canonical_json", "short_hash"]

_CHUNK = 1 << 20


def sha256_file(path):
    """Return the sha256 (64 hexadecimal characters) of a file's bytes, read in 1 MiB chunks.

    Parameters
    ----------
    path : str or os.PathLike
    """
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while chunk := stream.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def canonical_json(value):
    """Return ``value`` as canonical JSON: sorted keys, no spaces (equal values, equal text)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def short_hash(value, *parts):
    """Return a 16-hexadecimal-character id of a JSON-able value and optional further text parts.

    Parameters
    ----------
    value : object
        JSON-able (dicts, lists, strings, numbers, booleans, None).
    *parts : str
        Further text hashed after the value (e.g. the checksums of input files).

    Returns
    -------
    str
        The first 16 hexadecimal characters of the sha256 of the canonical JSON of
        ``value`` followed by ``parts``.
    """
    digest = hashlib.sha256(canonical_json(value).encode())
    for part in parts:
        digest.update(part.encode())
    return digest.hexdigest()[:16]
