"""Atomic, checksummed checkpoints that never execute code when read.

A checkpoint is two files in the checkpoint folder:

* ``step-NNNNNN.npz``: the arrays (``numpy.savez``; read with ``allow_pickle=False``),
* ``step-NNNNNN.json``: metadata (time, step, records, settings fingerprint) and the
  SHA-256 of the ``.npz`` bytes.

Each file is written to a temporary name in the same folder, flushed to disk and
renamed (``os.replace`` is atomic on POSIX and Windows), the ``.json`` last, so a
checkpoint whose ``.json`` exists is complete. :func:`load_latest` verifies the
checksum and falls back to the previous checkpoint when the newest is truncated or
corrupted, saying so in a logged warning.

When a write fails (full disk, lost permission) :func:`save` removes what it wrote
of the new checkpoint, keeps every older one and raises
:class:`CheckpointWriteError`, an :class:`~hmatddm.errors.OutputError` whose message
names the folder and says when the disk is full; the newest checkpoint on disk is
then the previous, complete one, and a resume after freeing space continues from it.
"""
import hashlib
import json
import logging
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from ..errors import HmatddmError, OutputError

logger = logging.getLogger(__name__)
_NAME = re.compile(r"^step-(\d{6,})\.json$")
FORMAT_VERSION = 1


class CheckpointError(HmatddmError):
    """No usable checkpoint, or a checkpoint folder that cannot be written."""


class CheckpointWriteError(CheckpointError, OutputError):
    """A checkpoint could not be written (full disk, folder not writable); both a
    CheckpointError and an OutputError (``disk_full`` tells the two apart)."""


def _atomic_write(path, write):
    """Write ``path`` through ``write(stream)`` into a temporary file that is flushed,
    fsync'ed and renamed over ``path``; on any error the temporary is removed and
    ``path`` is untouched. Returns ``path``."""
    path = Path(path)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise
    return path


def check_writable(folder, what="checkpoint folder"):
    """Create ``folder`` if needed and prove a file can be written there.

    Raises CheckpointWriteError (an OutputError) naming ``what`` and ``folder`` and the
    reason: not writable, read-only, or the disk is full."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        _atomic_write(folder / ".write-test", lambda stream: stream.write(b"ok"))
        (folder / ".write-test").unlink()
    except OSError as error:
        raise CheckpointWriteError(f"{what} {str(folder)!r} is not writable: "
                                   f"{OutputError.describe(error, folder)}", path=folder,
                                   errno=getattr(error, "errno", None)) from None
    return folder


def encoded_once(records, encoded, encode):
    """``[encode(record) for record in records]``, each record's text taken from ``encoded``
    (a dict the caller keeps, by identity) when it was encoded before, and kept there (None:
    nothing kept). Only for records that no longer change once encoded: a simulation's step
    records (:func:`metadata_text`, :func:`hmatddm.app.run_folder.json_text`)."""
    texts = []
    for record in records:
        known = None if encoded is None else encoded.get(id(record))
        if known is None or known[0] is not record:  # the record itself is held: no id reused
            known = (record, encode(record))
            if encoded is not None:
                encoded[id(record)] = known
        texts.append(known[1])
    return texts


def metadata_text(document, encoded=None):
    """The JSON text of a checkpoint's metadata: compact (json's C encoder), keys sorted, its
    ``records`` list spliced in from each record's text, encoded once when ``encoded`` (a
    dict the caller keeps between checkpoints, by identity) is given: the records of the
    accepted steps never change, and re-encoding all of them at every checkpoint, indented,
    made the checkpoints' cost grow as the steps squared (1.0 s of CPU in the 203 checkpoints
    of a 203-step run)."""
    records = document.get("records")
    if not isinstance(records, list):
        return json.dumps(document, sort_keys=True, allow_nan=False)
    texts = encoded_once(records, encoded, lambda record: json.dumps(record, sort_keys=True, allow_nan=False))
    rest = json.dumps({key: value for key, value in document.items() if key != "records"}, sort_keys=True,
                      allow_nan=False)
    spliced = '"records": [' + ", ".join(texts) + "]"
    return "{" + spliced + "}" if rest == "{}" else rest[:-1] + ", " + spliced + "}"


def save(folder, step, arrays, metadata, keep=3, encoded=None):
    """Write checkpoint ``step`` (arrays: dict of numpy arrays; metadata: JSON-able dict;
    ``encoded``: see :func:`metadata_text`).

    Keeps the newest ``keep`` checkpoints and deletes older ones.
    """
    folder = Path(folder)
    stem = f"step-{step:06d}"
    import io

    buffer = io.BytesIO()
    np.savez(buffer, **{key: np.asarray(value) for key, value in arrays.items()})
    payload = buffer.getvalue()
    digest = hashlib.sha256(payload).hexdigest()
    document = dict(metadata, format_version=FORMAT_VERSION, step=step, arrays_sha256=digest)
    text = metadata_text(document, encoded).encode()
    written = None
    try:
        written = _atomic_write(folder / f"{stem}.npz", lambda stream: stream.write(payload))
        _atomic_write(folder / f"{stem}.json", lambda stream: stream.write(text))
    except OSError as error:
        if written is not None:  # new arrays, old or no metadata: remove both, free the space
            for path in (written, folder / f"{stem}.json"):
                try:
                    path.unlink()
                except OSError:
                    pass
        reason = OutputError.from_os_error(error, folder / f"{stem}.json", what=f"checkpoint {stem}")
        kept = list_checkpoints(folder)
        previous = (f"; the newest complete checkpoint is step {kept[-1]}, which a resume continues from"
                    if kept else "")
        raise CheckpointWriteError(f"{reason}{previous}", path=reason.path, errno=reason.errno) from None
    for old in list_checkpoints(folder)[:-keep]:
        for suffix in (".json", ".npz"):
            try:
                (folder / f"step-{old:06d}{suffix}").unlink()
            except FileNotFoundError:
                pass


def list_checkpoints(folder):
    """Steps with a metadata file, ascending."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    return sorted(int(m.group(1)) for name in os.listdir(folder) if (m := _NAME.match(name)))


def load(folder, step):
    """``(arrays, metadata)`` of one checkpoint; CheckpointError if damaged."""
    folder = Path(folder)
    stem = f"step-{step:06d}"
    try:
        metadata = json.loads((folder / f"{stem}.json").read_text())
        payload = (folder / f"{stem}.npz").read_bytes()
    except (OSError, ValueError) as error:
        raise CheckpointError(f"checkpoint {stem} is unreadable: {error}") from None
    if metadata.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(f"checkpoint {stem} has format {metadata.get('format_version')!r}, "
                              f"expected {FORMAT_VERSION}")
    if hashlib.sha256(payload).hexdigest() != metadata.get("arrays_sha256"):
        raise CheckpointError(f"checkpoint {stem} is corrupted or truncated (SHA-256 mismatch)")
    import io

    with np.load(io.BytesIO(payload), allow_pickle=False) as data:
        arrays = {key: data[key] for key in data.files}
    return arrays, metadata


def load_latest(folder):
    """The newest checkpoint that verifies, falling back over damaged ones.

    Raises CheckpointError when there is none.
    """
    steps = list_checkpoints(folder)
    if not steps:
        raise CheckpointError(f"no checkpoint found in {str(folder)!r}")
    for step in reversed(steps):
        try:
            return load(folder, step)
        except CheckpointError as error:
            logger.warning("%s; trying the previous checkpoint", error)
    raise CheckpointError(f"every checkpoint in {str(folder)!r} is damaged")
