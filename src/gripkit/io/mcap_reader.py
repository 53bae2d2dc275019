"""ROS 2 logs in MCAP files (optional extra ``gripkit[mcap]``).

Columns are named ``[alias=]TOPIC:FIELD``, where FIELD is a dotted path into the message with
optional indices, e.g. ``force=/fingertip/wrench:wrench.force.z`` or
``q3=/joint_states:position[2]``.
Each topic has its own time stamps (the log time, or ``header.stamp`` with ``stamp='header'``);
the first column's topic sets the time base and the other columns are interpolated linearly onto
it, over the interval where every topic has data.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import DataError
from .table import check_size

__all__ = ["read_mcap", "parse_column"]

_COL = re.compile(r"^(?:(?P<alias>[A-Za-z_][\w]*)=)?"
                  r"(?P<topic>/[^:]*):(?P<field>[A-Za-z_][\w.\[\]]*)$")
_PART = re.compile(r"^([A-Za-z_]\w*)((?:\[\d+\])*)$")
_MAGIC = b"\x89MCAP0\r\n"  # the MCAP specification's leading magic bytes


def parse_column(spec: str) -> tuple[str, str, list]:
    """``'force=/ft:wrench.force.z'`` → ``('force', '/ft', ['wrench', 'force', 'z'])``."""
    m = _COL.match(spec)
    if not m:
        raise DataError(f"MCAP column {spec!r}: expected [alias=]/topic:field.path[index]",
                        hint="for example force=/fingertip/wrench:wrench.force.z or "
                             "/joint_states:position[2]")
    path: list = []
    for part in m.group("field").split("."):
        pm = _PART.match(part)
        if not pm:
            raise DataError(f"MCAP column {spec!r}: cannot read field part {part!r}")
        path.append(pm.group(1))
        path += [int(i) for i in re.findall(r"\[(\d+)\]", pm.group(2))]
    alias = (m.group("alias") or re.sub(r"\W+", "_",
                                        f"{m.group('topic')}_{m.group('field')}").strip("_"))
    return alias, m.group("topic"), path


def _get(msg, path: list, spec: str) -> float:
    v = msg
    for p in path:
        try:
            v = v[p] if isinstance(p, int) else getattr(v, p)
        except (AttributeError, IndexError, TypeError):
            raise DataError(f"MCAP column {spec!r}: the message has no field {p!r} "
                            "(fields: "
                            f"{', '.join(getattr(v, '__slots__', []) or dir(v)[:10])})"
                            ) from None
    try:
        return float(v)
    except (TypeError, ValueError):
        raise DataError(f"MCAP column {spec!r}: field is not a number ({type(v).__name__})",
                        hint="index into arrays (position[2]) or descend into messages "
                             "(wrench.force.z)") from None


def _check_declared_sizes(path: Path, reader, topics: set, ncols: int, limit: float) -> None:
    """Refuse, from the file's summary (when it has one), a chunk that declares more than the
    load limit uncompressed, or more messages on the topics read than the limit allows."""
    summary = reader.get_summary()
    if summary is None:
        return
    chunk = max((ci.uncompressed_size for ci in summary.chunk_indexes), default=0)
    if chunk > limit:
        raise DataError(f"{path.name}: a chunk of the MCAP file declares {chunk / 1e9:.3g} GB "
                        f"uncompressed, beyond the load limit of {limit / 1e9:.3g} GB; nothing was "
                        f"read",
                        hint="raise the limit with max_bytes= or the environment variable "
                             "GRIPKIT_MAX_LOAD_BYTES (bytes) if the machine has the memory")
    if summary.statistics is not None:
        counts = summary.statistics.channel_message_counts
        rows = sum(counts.get(cid, 0) for cid, ch in summary.channels.items() if ch.topic in topics)
        check_size(path.name, "the MCAP file", rows, ncols + 1, limit)


def read_mcap(path: Path, columns, stamp: str = "log",
              limit: float = float("inf")) -> tuple[dict, dict]:
    try:
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:
        raise DataError("reading MCAP files needs "
                        "the optional extra", hint="pip install 'gripkit[mcap]'") from None
    with open(path, "rb") as fh:
        if fh.read(len(_MAGIC)) != _MAGIC:
            raise DataError(f"{path.name}: not an MCAP file (it does not start with the "
                            "MCAP magic bytes)",
                            hint="check the file, or force another format with "
                                 "format='csv'|'parquet'|'hdf5'")
    if not columns:
        raise DataError(f"{path.name}: name the MCAP columns to read (gripkit.io.load(path, "
                        f"columns=[...]))",
                        hint="columns look like force=/fingertip/wrench:wrench.force.z; the "
                             "commands take the same names as their column options "
                             "(--input /cmd:data[0] --output force=/ft:wrench.force.z)")
    specs = [parse_column(c) for c in columns]
    topics = {t for _, t, _ in specs}
    series: dict[str, tuple[list, list]] = {alias: ([], []) for alias, _, _ in specs}
    seen: set[str] = set()
    try:
        with open(path, "rb") as fh:
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            _check_declared_sizes(path, reader, topics, len(specs), limit)
            for _schema, channel, message, msg in reader.iter_decoded_messages(topics=list(topics)):
                topic = channel.topic
                seen.add(topic)
                if stamp == "header":  # integer nanoseconds: a float loses 238 ns at 1.7e9 s
                    st = msg.header.stamp
                    t = int(st.sec) * 1_000_000_000 + int(st.nanosec)
                else:
                    t = int(message.log_time)
                for (alias, top, fpath), spec in zip(specs, columns):
                    if top == topic:
                        series[alias][0].append(t)
                        series[alias][1].append(_get(msg, fpath, spec))
    except DataError:
        raise
    except Exception as exc:
        raise DataError(f"{path.name}: not a readable MCAP file (truncated or "
                        f"corrupt?): {exc}") from None
    missing = sorted(topics - seen)
    if missing:
        raise DataError(f"{path.name}: no messages on topics {missing}")
    # seconds after the earliest stamp, subtracted in integer nanoseconds so that none is lost
    first = min(min(series[a][0]) for a in series)
    series = {a: ((np.asarray(ts, dtype=np.int64) - first) * 1e-9, vs)
              for a, (ts, vs) in series.items()}
    base_alias = specs[0][0]
    tb = np.asarray(series[base_alias][0])
    ob = np.argsort(tb, kind="stable")
    tb = tb[ob]
    lo = max(np.min(series[a][0]) for a in series)
    hi = min(np.max(series[a][0]) for a in series)
    keep = (tb >= lo) & (tb <= hi)
    if keep.sum() < 2:
        raise DataError(f"{path.name}: the topics' time spans do not overlap")
    t = tb[keep]
    raw = {"t": t - t[0]}
    for alias, _, _ in specs:
        ts, vs = np.asarray(series[alias][0]), np.asarray(series[alias][1])
        order = np.argsort(ts, kind="stable")
        raw[alias] = vs[ob][keep] if alias == base_alias else np.interp(t, ts[order], vs[order])
    return raw, {"t": "s"}
