"""`rbsim log filter` and `rbsim log merge` done independently with the official Python `mcap`
reader and writer (the venv scripts/setup makes): the reference test/python/check_log_tools.py
checks rbsim's output against, and the peer scripts/bench-log-tools times it against. Written from
the README's description of the commands, sharing no code with them."""

import heapq

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

# rbsim's latched topics, by type (the scene description and the markers): a window keeps the last
# message of each from before its start.
LATCHED_TYPES = {"rbsim_msgs/msg/SceneDescription", "visualization_msgs/msg/MarkerArray"}

COMPRESSION = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}


class _Output:
    """A writer whose schemas and channels are written once per distinct content."""

    def __init__(self, stream, profile, compression, chunk_size):
        self.writer = Writer(stream, chunk_size=chunk_size, compression=COMPRESSION[compression])
        self.writer.start(profile=profile, library="mcap_reference.py")
        self.schemas, self.channels = {}, {}

    def channel(self, schema, channel, topic):
        schema_id = 0
        if schema is not None:
            key = (schema.name, schema.encoding, bytes(schema.data))
            if key not in self.schemas:
                self.schemas[key] = self.writer.register_schema(schema.name, schema.encoding, schema.data)
            schema_id = self.schemas[key]
        key = (topic, channel.message_encoding, schema_id, tuple(sorted(channel.metadata.items())))
        if key not in self.channels:
            self.channels[key] = self.writer.register_channel(topic, channel.message_encoding, schema_id,
                                                              dict(channel.metadata))
        return self.channels[key]

    def write(self, channel_id, message):
        self.writer.add_message(channel_id, message.log_time, message.data, message.publish_time,
                                message.sequence)

    def finish(self):
        self.writer.finish()


def filter_file(src, dst, start_ns=0, end_ns=None, topics=None, compression="zstd", chunk_size=1 << 20):
    """Messages of `src` with start_ns <= log time < end_ns (on `topics`, all if None), in log-time
    order, after the last message before start_ns of each latched topic kept."""
    with open(src, "rb") as f, open(dst, "wb") as out:
        reader = make_reader(f)
        summary = reader.get_summary()
        output = _Output(out, reader.get_header().profile, compression, chunk_size)
        ids = {}
        for cid, channel in summary.channels.items():  # every kept channel listed
            if topics is None or channel.topic in topics:
                ids[cid] = output.channel(summary.schemas.get(channel.schema_id), channel, channel.topic)
        if start_ns > 0:
            last = {}
            for schema, channel, message in reader.iter_messages(end_time=start_ns, log_time_order=True):
                if channel.id in ids and schema is not None and schema.name in LATCHED_TYPES:
                    last[channel.id] = message
            for cid, message in sorted(last.items(), key=lambda kv: kv[1].log_time):
                output.write(ids[cid], message)
        for schema, channel, message in reader.iter_messages(start_time=start_ns, end_time=end_ns,
                                                             log_time_order=True):
            if channel.id in ids:
                output.write(ids[channel.id], message)
        output.finish()


def merge_files(srcs, dst, namespaces=None, compression="zstd", chunk_size=1 << 20):
    """Every message of `srcs` in log-time order, equal times in the order of `srcs` (heapq.merge is
    stable), each input's topics under its namespace ("" or "/": none)."""
    files = [open(s, "rb") for s in srcs]
    try:
        readers = [make_reader(f) for f in files]
        prefixes = [(ns or "").rstrip("/") for ns in (namespaces or [""] * len(srcs))]
        with open(dst, "wb") as out:
            output = _Output(out, readers[0].get_header().profile, compression, chunk_size)
            ids = []
            for reader, prefix in zip(readers, prefixes):
                summary = reader.get_summary()
                ids.append({cid: output.channel(summary.schemas.get(c.schema_id), c, prefix + c.topic)
                            for cid, c in summary.channels.items()})
            def stream(reader, route):
                for _, c, m in reader.iter_messages(log_time_order=True):
                    yield m.log_time, route[c.id], m

            streams = [stream(r, route) for r, route in zip(readers, ids)]
            for _, cid, message in heapq.merge(*streams, key=lambda t: t[0]):
                output.write(cid, message)
            output.finish()
    finally:
        for f in files:
            f.close()
