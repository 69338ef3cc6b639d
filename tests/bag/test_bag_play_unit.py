"""Player and recorder logic with fake nodes and clocks: schedule, rate, latching, drops, naming."""

from __future__ import annotations

import io

import pytest
from bagtest_util import BASE, STRING_HEADER, string_bytes

from ninjemys.bag.format import NSEC
from ninjemys.bag.play import Player, PlayOptions
from ninjemys.bag.record import BagNamer, ByteBoundedQueue, RecordOptions, parse_duration
from ninjemys.bag.writer import BagWriter
from ninjemys.errors import BagError


class FakeTime:
    """Monotonic clock that advances only when slept on (plus a fixed overshoot per sleep)."""

    def __init__(self, overshoot: float = 0.0) -> None:
        self.now = 100.0
        self.overshoot = overshoot

    def monotonic(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += max(seconds, 0.0) + self.overshoot


class FakePub:
    def __init__(self, log, topic, cls, latch):
        self.log, self.topic, self.cls, self.latch = log, topic, cls, latch

    def publish_raw(self, data):
        self.log.append((self.topic, bytes(data)))

    def get_num_connections(self):
        return 1


class FakeNode:
    def __init__(self, clock: FakeTime) -> None:
        self.clock = clock
        self.sent: list = []
        self.pubs: dict = {}

    def publisher(self, topic, cls, queue_size=None, latch=False):
        log = []
        pub = FakePub(log, topic, cls, latch)

        def publish_raw(data, topic=topic):
            self.sent.append((self.clock.now, topic, bytes(data)))

        pub.publish_raw = publish_raw
        self.pubs[topic] = pub
        return pub


def make_bag(path, gaps_ms):
    with BagWriter(path) as w:
        c = w.connection("/a", STRING_HEADER)
        lat = w.connection("/latched", dict(STRING_HEADER, latching=b"1"))
        t = BASE
        for i, gap in enumerate(gaps_ms):
            t += gap * 1_000_000
            w.write(c, t, string_bytes(str(i)))
        w.write(lat, BASE, string_bytes("map"))
    return path


@pytest.mark.parametrize("rate", [1.0, 2.0, 0.5])
def test_schedule_follows_recorded_gaps_without_drift(tmp_path, rate):
    gaps = [0, 10, 250, 1, 1, 1, 500, 33, 33, 34] * 5
    bag = make_bag(tmp_path / "a.bag", gaps)
    clock = FakeTime(overshoot=0.0007)  # every sleep overshoots: errors must not accumulate
    node = FakeNode(clock)
    player = Player(
        node,
        PlayOptions(bags=[str(bag)], rate=rate, delay=0, quiet=True, topics=["/a"]),
        sleep=clock.sleep,
        monotonic=clock.monotonic,
    )
    player.run()
    times = [t for t, topic, _ in node.sent if topic == "/a"]
    assert len(times) == len(gaps)
    start = times[0]
    cumulative = 0
    for i, t in enumerate(times):
        cumulative += gaps[i] if i else 0
        assert abs((t - start) - cumulative / 1000 / rate) <= 0.0008


def test_latched_connections_are_relatched_and_types_kept(tmp_path):
    bag = make_bag(tmp_path / "a.bag", [0, 10])
    clock = FakeTime()
    node = FakeNode(clock)
    Player(
        node, PlayOptions(bags=[str(bag)], delay=0, quiet=True), sleep=clock.sleep, monotonic=clock.monotonic
    ).run()
    assert node.pubs["/latched"].latch and not node.pubs["/a"].latch
    assert node.pubs["/a"].cls._md5sum == "992ce8a1687cec8c8bd883ec73ca41d1"
    assert node.pubs["/a"].cls._full_text == "string data\n"


def test_clock_is_published_with_bag_time(tmp_path):
    bag = make_bag(tmp_path / "a.bag", [0, 100, 100])
    clock = FakeTime()
    node = FakeNode(clock)
    opts = PlayOptions(bags=[str(bag)], delay=0, quiet=True, clock=True, hz=100, topics=["/a"])
    Player(node, opts, sleep=clock.sleep, monotonic=clock.monotonic).run()
    import struct

    stamps = [struct.unpack("<II", d) for _, topic, d in node.sent if topic == "/clock"]
    ns = [s * NSEC + n for s, n in stamps]
    assert len(ns) >= 20  # 200 ms of bag at 100 Hz
    assert ns == sorted(ns) and ns[0] >= BASE and ns[-1] == BASE + 200_000_000


def test_start_duration_and_immediate(tmp_path):
    bag = make_bag(tmp_path / "a.bag", [0] + [100] * 9)
    clock = FakeTime()
    node = FakeNode(clock)
    opts = PlayOptions(
        bags=[str(bag)], delay=0, quiet=True, immediate=True, start=0.25, duration=0.3, topics=["/a"]
    )
    Player(node, opts, sleep=clock.sleep, monotonic=clock.monotonic).run()
    assert [d for _, _, d in node.sent] == [string_bytes(str(i)) for i in (3, 4, 5)]
    assert clock.now == 100.0  # immediate: never slept


def test_pause_and_step_with_keys(tmp_path):
    bag = make_bag(tmp_path / "a.bag", [0, 100, 100])
    clock = FakeTime()
    node = FakeNode(clock)

    class Keys:
        active = True
        script = ["s", None, None, "s", None, " "]

        def read(self):
            return self.script.pop(0) if self.script else None

    out = io.StringIO()
    opts = PlayOptions(bags=[str(bag)], delay=0, pause=True, topics=["/a"])
    Player(node, opts, out=out, keyboard=Keys(), sleep=clock.sleep, monotonic=clock.monotonic).run()
    assert len(node.sent) == 3
    assert "[PAUSED ]" in out.getvalue() and "Done." in out.getvalue()


def test_status_line_layout(tmp_path):
    bag = make_bag(tmp_path / "a.bag", [0, 300, 300])
    clock = FakeTime()
    out = io.StringIO()
    Player(
        FakeNode(clock),
        PlayOptions(bags=[str(bag)], delay=0, topics=["/a"]),
        out=out,
        sleep=clock.sleep,
        monotonic=clock.monotonic,
    ).run()
    assert " [RUNNING]  Bag Time: 1700000000.300000   Duration: 0.300000 / 0.600000" in out.getvalue()


def test_byte_bounded_queue_drops_oldest_and_counts():
    dropped = []
    q = ByteBoundedQueue(1000, dropped.append)
    for i in range(10):
        q.put("/big", {}, bytes(300), i)
    assert q.bytes <= 1000 and len(q) == 3
    assert dropped == ["/big"] * 7
    assert [q.get(0)[3] for _ in range(3)] == [7, 8, 9]
    assert q.get(0) is None


def test_names_and_durations():
    assert BagNamer(RecordOptions(output_name="run")).next().name == "run.bag"
    namer = BagNamer(RecordOptions(output_name="run.bag", split=True))
    assert [namer.next().name for _ in range(2)] == ["run_0.bag", "run_1.bag"]
    assert BagNamer(RecordOptions(output_prefix="pre")).next().name.startswith("pre_20")
    assert parse_duration("30") == 30 and parse_duration("5m") == 300 and parse_duration("2h") == 7200
    with pytest.raises(BagError):
        parse_duration("soon")


class FakeRecordNode:
    def __init__(self):
        self.callbacks = {}

    def resolve_name(self, name):
        return name if name.startswith("/") else "/" + name

    def get_param(self, key, default=None):
        return default

    def subscriber(self, topic, cls, callback, raw=False):
        assert cls is None and raw
        self.callbacks[topic] = callback

        class Handle:
            def unregister(self_inner):
                self.callbacks.pop(topic, None)

        return Handle()


class Raw:
    def __init__(self, data, header):
        self.data, self.connection_header = data, header


def test_recorder_counts_and_reports_drops_when_the_buffer_is_full(tmp_path, monkeypatch):
    from ninjemys.bag.reader import BagReader
    from ninjemys.bag.record import Recorder

    monkeypatch.chdir(tmp_path)
    node = FakeRecordNode()
    logs = []
    rec = Recorder(node, RecordOptions(topics=["/big"], output_name="drops", buffsize=10_000), logs.append)
    rec._subscribe("/big")
    header = {
        "type": "std_msgs/String",
        "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
        "message_definition": "string data\n",
        "callerid": "/pub",
    }
    for i in range(50):  # the writer thread is not running yet: the queue must bound itself
        node.callbacks["/big"](Raw(string_bytes(f"{i:04d}" + "x" * 996), header))
    assert rec.totals.dropped_total == 41 and rec.queue.bytes <= 10_000
    assert any("buffer exceeded" in line for line in logs)
    rec.start()
    rec.stop()
    assert "dropped 41" in rec.summary()
    with BagReader(tmp_path / "drops.bag") as r:
        got = [bytes(m.data)[4:8] for m in r.read()]
        assert r.topic_connections("/big")[0].callerid == "/pub"
    assert got == [b"%04d" % i for i in range(41, 50)]  # the oldest were dropped, the newest kept


def test_recorder_regex_and_exclude_select_topics():
    from ninjemys.bag.record import Recorder

    node = FakeRecordNode()
    rec = Recorder(node, RecordOptions(topics=["/a_.*"], regex=True, exclude="_2$"))
    assert rec._wanted("/a_1") and not rec._wanted("/a_2") and not rec._wanted("/b")
    rec_all = Recorder(node, RecordOptions(all=True, exclude="/rosout"))
    assert rec_all._wanted("/anything") and not rec_all._wanted("/rosout_agg")


def test_progress_line_has_percentage_and_eta():
    from ninjemys.bag.progress import Progress

    p = Progress("out.bag", 1000, stream=io.StringIO(), enabled=True)
    p.started = 0.0
    p.done = 250
    line = p.line(10.0, final=False)
    assert "out.bag" in line and " 25%" in line and "00:30 ETA" in line
    p.done = 1000
    assert "100%" in p.line(40.0, final=True)
    quiet = io.StringIO()
    silent = Progress("x", 10, stream=quiet)  # not a terminal: draws nothing
    silent.step(5)
    silent.finish()
    assert quiet.getvalue() == ""


def test_recorder_node_option_follows_a_nodes_subscriptions():
    from ninjemys.bag.record import Recorder

    node = FakeRecordNode()

    class Master:
        def get_system_state(self):
            return [
                [["/pub_only", ["/talker"]]],
                [["/scan", ["/mapper"]], ["/odom", ["/mapper", "/x"]], ["/other", ["/x"]]],
                [],
            ]

    node.master = Master()
    rec = Recorder(node, RecordOptions(node="/mapper"))
    rec._discover()
    assert sorted(node.callbacks) == ["/odom", "/scan"]


def test_split_by_size_repeats_latched_messages_in_every_bag(tmp_path, monkeypatch):
    from ninjemys.bag.reader import BagReader
    from ninjemys.bag.record import Recorder

    monkeypatch.chdir(tmp_path)
    node = FakeRecordNode()
    opts = RecordOptions(
        topics=["/map", "/scan"], output_name="s", split=True, split_size=20_000, repeat_latched=True
    )
    rec = Recorder(node, opts)
    rec.start()
    latched = {
        "type": "std_msgs/String",
        "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
        "message_definition": "string data\n",
        "latching": "1",
        "callerid": "/map_server",
    }
    plain = dict(latched, latching="0", callerid="/laser")
    node.callbacks["/map"](Raw(string_bytes("the map"), latched))
    for i in range(60):
        node.callbacks["/scan"](Raw(string_bytes(f"{i:04d}" + "s" * 1000), plain))
    rec.stop()
    assert len(rec.paths) >= 3
    total_scans = 0
    for path in rec.paths:
        with BagReader(path) as r:
            assert r.indexed
            topics = [(m.connection.topic, bytes(m.data)) for m in r.read()]
        assert ("/map", string_bytes("the map")) in topics  # every split bag has the latched map
        total_scans += sum(1 for t, _ in topics if t == "/scan")
    assert total_scans == 60


def test_command_line_options_parse_into_options():
    from ninjemys.bag import play, record

    r = record.options_from_args(
        record.build_parser().parse_intermixed_args(
            [
                "/a",
                "-O",
                "x",
                "/b",
                "--lz4",
                "--split",
                "--size",
                "2",
                "--max-splits",
                "3",
                "-b",
                "16",
                "--chunksize",
                "512",
                "-l",
                "9",
                "--repeat-latched",
                "--stats",
                "2",
                "-x",
                "/b",
            ]
        )
    )
    assert (r.topics, r.output_name, r.compression, r.split_size, r.max_splits) == (
        ["/a", "/b"],
        "x",
        "lz4",
        2 << 20,
        3,
    )
    assert (r.buffsize, r.chunksize, r.limit, r.repeat_latched, r.stats, r.exclude) == (
        16 << 20,
        512 << 10,
        9,
        True,
        2.0,
        "/b",
    )
    assert (
        record.options_from_args(
            record.build_parser().parse_intermixed_args(["-a", "-j", "--duration", "1m"])
        ).split_duration
        == 60
    )
    p = play.options_from_args(
        play.build_parser().parse_intermixed_args(
            [
                "a.bag",
                "-r",
                "2",
                "b.bag",
                "-s",
                "1",
                "-u",
                "3",
                "-l",
                "--clock",
                "--hz",
                "50",
                "-d",
                "0",
                "-k",
                "--pause",
                "-q",
                "-i",
                "--topics",
                "/x",
                "/y",
            ]
        )
    )
    assert (p.bags, p.rate, p.start, p.duration, p.loop, p.clock, p.hz) == (
        ["a.bag", "b.bag"],
        2.0,
        1.0,
        3.0,
        True,
        True,
        50.0,
    )
    assert (p.delay, p.keep_alive, p.pause, p.quiet, p.immediate, p.topics) == (
        0.0,
        True,
        True,
        True,
        True,
        ["/x", "/y"],
    )
    with pytest.raises(BagError):
        record.options_from_args(record.build_parser().parse_intermixed_args([]))
    with pytest.raises(BagError):
        play.options_from_args(play.build_parser().parse_intermixed_args(["a.bag", "-r", "0"]))


def test_empty_bag_and_window_past_the_end_play_nothing(tmp_path):
    empty = tmp_path / "empty.bag"
    BagWriter(empty).close()
    bag = make_bag(tmp_path / "a.bag", [0, 10])
    for opts in (
        PlayOptions(bags=[str(empty)], delay=0, quiet=True),
        PlayOptions(bags=[str(bag)], delay=0, quiet=True, start=100.0),
    ):
        clock = FakeTime()
        node = FakeNode(clock)
        Player(node, opts, sleep=clock.sleep, monotonic=clock.monotonic).run()
        assert node.sent == []


def test_two_bags_are_merged_in_time_order(tmp_path):
    a = tmp_path / "a.bag"
    b = tmp_path / "b.bag"
    for path, offset in ((a, 0), (b, 5)):
        with BagWriter(path) as w:
            c = w.connection("/a", STRING_HEADER)
            for i in range(5):
                w.write(c, BASE + (i * 10 + offset) * 1_000_000, string_bytes(f"{path.stem}{i}"))
    clock = FakeTime()
    node = FakeNode(clock)
    Player(
        node,
        PlayOptions(bags=[str(a), str(b)], delay=0, quiet=True),
        sleep=clock.sleep,
        monotonic=clock.monotonic,
    ).run()
    assert [d[4:].decode() for _, _, d in node.sent] == [f"{s}{i}" for i in range(5) for s in "ab"]
