"""MCAP logs read back with the `mcap` package (an implementation independent of the Rust
writer and reader): CRCs valid, schemas parse, per-topic counts equal the run's own
counts, the event trace equals the golden trace, attachments and metadata replay the run.

Run by scripts/test after `cargo test` has built target/debug/vworks (or set VWORKS).
"""

import json
import os
import pathlib
import subprocess
import tempfile

import pytest
from google.protobuf import descriptor_pb2
from mcap.reader import make_reader

ROOT = pathlib.Path(__file__).resolve().parents[2]
VWORKS = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))
CELLS = ["handoff", "weldline", "monitor", "crash", "deadlock", "track", "palletize"]


def run_logged(cell, *extra):
    """Runs a bundled cell with --log; returns (the run's JSON result, the log's bytes)."""
    with tempfile.TemporaryDirectory() as tmp:
        log = pathlib.Path(tmp) / "run.mcap"
        proc = subprocess.run(
            [VWORKS, "run", str(ROOT / "workcells" / cell / "cell.toml"), "--log", str(log), "--json", *extra],
            capture_output=True,
            text=True,
            check=False,
        )
        assert proc.returncode in (0, 1), proc.stderr
        return json.loads(proc.stdout), log.read_bytes()


def trace_line(event):
    """An /events message as a golden-trace line: `time robot kind details file:line:col`."""
    pos = "-"
    if event.get("file"):
        pos = f"{pathlib.Path(event['file']).name}:{event['line']}:{event['col']}"
    return " ".join(
        [str(event["time_ns"]), event.get("robot") or "-", event["kind"], event.get("details") or "-", pos]
    )


def read(data):
    """Every message (chunk CRCs checked), per-topic counts and the event lines."""
    import io

    reader = make_reader(io.BytesIO(data), validate_crcs=True)
    summary = reader.get_summary()
    assert summary is not None, "a finished log has a summary"
    counts = {c.topic: 0 for c in summary.channels.values()}
    events = []
    for schema, channel, message in reader.iter_messages():
        counts[channel.topic] += 1
        if schema.encoding == "jsonschema":
            json.loads(schema.data)
            body = json.loads(message.data)
            if channel.topic == "/events":
                events.append(trace_line(body))
        else:
            assert schema.encoding == "protobuf" and channel.message_encoding == "protobuf"
            descriptors = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
            names = {f"{f.package}.{m.name}" for f in descriptors.file for m in f.message_type}
            assert schema.name in names
    return reader, summary, counts, events


@pytest.mark.parametrize("cell", CELLS)
def test_log_matches_run_and_golden_trace(cell):
    result, data = run_logged(cell)
    _, summary, counts, events = read(data)
    assert counts == result["log"]["messages"]
    assert summary.statistics.message_count == sum(counts.values())
    assert counts["/events"] == result["events"]
    lines = (ROOT / "tests" / "golden" / f"{cell}.trace").read_text().splitlines()
    assert events == [line for line in lines if not line.startswith("#")]
    # The golden file ends with `# outcome KIND at N ns`: the same run.
    assert f"# outcome {result['outcome']} at {result['end_time_ns']} ns" in lines


def test_until_thinned_log():
    result, data = run_logged("handoff", "--until", "5s", "--log-every", "10")
    assert result["outcome"] == "until"
    _, _, counts, _ = read(data)
    assert counts == result["log"]["messages"]
    assert counts["/state"] == -(-result["cycles"] // 10)  # every 10th boundary, from the first


def test_attachments_and_metadata_replay_the_run():
    import io

    _, data = run_logged("handoff", "--until", "1s")
    reader = make_reader(io.BytesIO(data), validate_crcs=True)
    attached = {pathlib.Path(a.name).name: a.data for a in reader.iter_attachments()}
    assert sorted(attached) == ["cell.toml", "r1.wsl", "r2.wsl"]
    for name, body in attached.items():
        assert body == (ROOT / "workcells" / "handoff" / name).read_bytes()
    (meta,) = [m for m in reader.iter_metadata() if m.name == "vworks"]
    assert meta.metadata["cell"] == "handoff"
    assert int(meta.metadata["cycle_ns"]) > 0
    assert meta.metadata["robots"] == "r1,r2"


def message_classes(reader):
    """Message classes built from each protobuf channel's own schema (FileDescriptorSet)."""
    from google.protobuf import descriptor_pool, message_factory

    classes = {}
    summary = reader.get_summary()
    for channel in summary.channels.values():
        schema = summary.schemas[channel.schema_id]
        if schema.encoding != "protobuf":
            continue
        pool = descriptor_pool.DescriptorPool()
        for proto in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
            pool.Add(proto)
        classes[channel.topic] = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
    return classes


def test_state_and_tf_decode_with_their_own_schemas():
    import io
    import math

    result, data = run_logged("handoff", "--until", "3s")
    reader = make_reader(io.BytesIO(data), validate_crcs=True)
    classes = message_classes(reader)
    assert sorted(classes) == ["/state", "/tf"]
    states = 0
    parents = {}
    for _, channel, message in reader.iter_messages(topics=["/state", "/tf"]):
        decoded = classes[channel.topic].FromString(message.data)
        if channel.topic == "/state":
            states += 1
            assert decoded.time_ns == message.log_time
            assert decoded.cycle == states - 1
            assert [r.name for r in decoded.robots] == ["r1", "r2"]
            for robot in decoded.robots:
                assert len(robot.joints) == 6
                o = robot.tcp.orientation
                assert math.isclose(o.x**2 + o.y**2 + o.z**2 + o.w**2, 1.0, rel_tol=1e-12)
        else:
            for t in decoded.transforms:
                assert t.timestamp.seconds * 10**9 + t.timestamp.nanos == message.log_time
                assert parents.setdefault(t.child_frame_id, t.parent_frame_id) == t.parent_frame_id
    assert states == result["log"]["messages"]["/state"]
    # A tree: every frame reaches `world` through its parents.
    for frame in parents:
        seen = set()
        while frame != "world":
            assert frame not in seen
            seen.add(frame)
            frame = parents[frame]
    assert parents["r1.base_link"] == "world" and parents["r1.link_1"] == "r1.base_link"
