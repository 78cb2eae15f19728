"""Read MCAP files with the official Python reader and print what they hold as JSON.

Usage: scripts/mcap-python tests/all/support/read_mcap.py FILE...

For each file: the header profile and library, the schemas (name, encoding, text), the
channels (topic, schema name, message encoding, message count counted by iterating every
message with CRC validation), the statistics record's counts, the metadata records, every
message of every channel decoded from JSON (numbers as exact text, see `exact`), and the first and last log_time per channel.
The Rust test compares this with what settle wrote.
"""

import json
import sys

from mcap.reader import make_reader


def exact(value):
    """Numbers as text the Rust side parses exactly: float -> "f:<repr>", int -> "i:<n>"."""
    if isinstance(value, bool):
        return value
    if isinstance(value, float):
        return "f:" + repr(value)
    if isinstance(value, int):
        return "i:" + str(value)
    if isinstance(value, dict):
        return {k: exact(v) for k, v in value.items()}
    if isinstance(value, list):
        return [exact(v) for v in value]
    return value


def read(path):
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        header = reader.get_header()
        summary = reader.get_summary()
        schemas = {
            sid: {"name": s.name, "encoding": s.encoding, "data": s.data.decode("utf-8")}
            for sid, s in summary.schemas.items()
        }
        channels = {}
        for cid, c in summary.channels.items():
            channels[cid] = {
                "topic": c.topic,
                "message_encoding": c.message_encoding,
                "schema": schemas[c.schema_id],
                "count": 0,
                "messages": [],
                "log_times": [],
            }
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            ch = channels[channel.id]
            ch["count"] += 1
            ch["messages"].append(exact(json.loads(message.data)))
            ch["log_times"].append(message.log_time)
        metadata = [
            {"name": m.name, "metadata": dict(m.metadata)} for m in reader.iter_metadata()
        ]
        stats = summary.statistics
        return {
            "profile": header.profile,
            "library": header.library,
            "channels": sorted(channels.values(), key=lambda c: c["topic"]),
            "statistics": {
                "message_count": stats.message_count,
                "schema_count": stats.schema_count,
                "channel_count": stats.channel_count,
                "metadata_count": stats.metadata_count,
                "chunk_count": stats.chunk_count,
                "channel_message_counts": {
                    channels[cid]["topic"]: n for cid, n in stats.channel_message_counts.items()
                },
            },
            "compression": sorted({ci.compression for ci in summary.chunk_indexes}),
            "metadata": metadata,
        }


def main():
    out = {path: read(path) for path in sys.argv[1:]}
    json.dump(out, sys.stdout, allow_nan=False)


if __name__ == "__main__":
    main()
