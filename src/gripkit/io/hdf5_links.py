"""HDF5 objects that stay in their file: a path below a group followed link by link (external
links to other files refused unless allowed, soft links by their own path), and datasets whose
values live in other files (external raw storage, virtual datasets) refused. Used by the HDF5 and
the MATLAB 7.3 readers (:mod:`gripkit.io.formats`, :mod:`gripkit.io.mat_reader`)."""

from __future__ import annotations

from ..errors import DataError

__all__ = ["EXTERNAL_HINT", "check_dataset", "hdf5_get", "hdf5_open", "hdf5_text"]


def hdf5_open(path, what: str):
    """The file ``path`` opened read-only by h5py; one h5py cannot open (truncated, corrupt, not
    HDF5) is a DataError naming the file and ``what`` it should be (``'HDF5 file'``)."""
    import h5py

    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise DataError(f"{path.name}: not a readable {what} (truncated or "
                        f"corrupt?): {exc}") from None


def hdf5_text(x) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)


EXTERNAL_HINT = ("pass allow_external_links=True (CLI: gripkit --allow-external-links) if you "
                  "trust this file, or copy the data into it")


def hdf5_get(group, name: str, source: str, allow_external: bool, depth: int = 0):
    """The object at the path ``name`` below ``group`` (None if absent), following each link
    along the path only while it stays in the file: an external link (to another file) is refused
    unless ``allow_external``; a soft link is followed by its own path (at most 16 deep)."""
    import h5py

    if depth > 16:
        raise DataError(f"{source}: soft links nest more than 16 deep at {name!r} (a cycle?)")
    node = group.file["/"] if name.startswith("/") else group
    for part in [p for p in name.split("/") if p]:
        if not isinstance(node, h5py.Group):
            return None
        link = node.get(part, getlink=True)
        if link is None:
            return None
        if isinstance(link, h5py.ExternalLink):
            if not allow_external:
                raise DataError(
                    f"{source}: {node.name.rstrip('/') + '/' + part!r} is an external link to "
                    f"{hdf5_text(link.filename)!r}:{hdf5_text(link.path)!r}, another file; "
                    f"not followed", hint=EXTERNAL_HINT)
            node = node[part]
        elif isinstance(link, h5py.SoftLink):
            node = hdf5_get(node, link.path, source, allow_external, depth + 1)
            if node is None:
                return None
        else:
            node = node[part]
    return node


def check_dataset(ds, source: str, allow_external: bool) -> None:
    """Refuse a dataset whose values come from other files: external raw storage (any file the
    HDF5 file names) or a virtual dataset (a map onto datasets of other files)."""
    if allow_external:
        return
    if ds.is_virtual:
        raise DataError(f"{source}: dataset {ds.name!r} is a virtual dataset (its values are read "
                        f"from other datasets or files); not read", hint=EXTERNAL_HINT)
    if ds.external:
        raise DataError(f"{source}: dataset {ds.name!r} keeps its values in an external file "
                        f"({hdf5_text(ds.external[0][0])!r}), not in this file; not read",
                        hint=EXTERNAL_HINT)
