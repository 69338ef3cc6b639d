"""What a node process pays at start-up and exit: modules it must not import, and an exit right after
init_node that still leaves the master clean (whether or not /rosout was set up by then)."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys

import pytest
from node_harness import MasterProcess

from ninjemys.idl.spec import Constant, Field, FieldType, MsgSpec
from ninjemys.master.client import MasterClient
from ninjemys.testing import wait_until

#: imported by nothing on the `import rospy; rospy.init_node()` path (each costs milliseconds)
NEVER_IMPORTED = ("asyncio", "concurrent.futures", "ssl", "subprocess", "encodings.idna")


def _env(master_uri: str = "http://localhost:1/") -> dict[str, str]:
    env = dict(os.environ, ROS_MASTER_URI=master_uri, ROS_HOSTNAME="localhost")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _imported_after(code: str, env: dict[str, str]) -> set[str]:
    probe = code + "\nimport sys\nprint(' '.join(sorted(sys.modules)))\n"
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return set(out.stdout.split())


def test_import_rospy_loads_no_event_loop_and_no_interface_loader() -> None:
    modules = _imported_after("import rospy", _env())
    heavy = {"asyncio", "concurrent.futures", "ssl", "subprocess", "ninjemys.idl.loader", "hashlib"}
    assert not heavy & modules, heavy & modules
    assert "ninjemys.idl.hook" in modules  # `from my_pkg.msg import X` still works (lazily)


def test_init_node_loads_no_asyncio(master: MasterProcess) -> None:
    code = "import rospy\nrospy.init_node('probe_imports', anonymous=True)"
    modules = _imported_after(code, _env(master.uri))
    assert not set(NEVER_IMPORTED) & modules, set(NEVER_IMPORTED) & modules
    assert "ninjemys.net.loop" in modules


def test_message_import_through_the_lazy_hook() -> None:
    code = "import rospy\nfrom rosgraph_msgs.msg import Log\nassert Log._type == 'rosgraph_msgs/Log'"
    modules = _imported_after(code, _env())
    assert "ninjemys.idl.loader" in modules


@pytest.mark.parametrize("linger", ["0", "0.3"])
def test_exit_right_after_init_node_leaves_the_master_clean(master: MasterProcess, linger: str) -> None:
    """linger 0: the process exits before /rosout is set up; 0.3: after. Either way nothing stays."""
    code = (
        "import sys, time, rospy\n"
        "rospy.init_node('quick_exit')\n"
        "time.sleep(float(sys.argv[1]))\n"
        "print(rospy.get_node_uri(), flush=True)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code, linger], env=_env(master.uri), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr
    client = MasterClient(master.uri, "/probe", timeout=2.0)
    try:

        def leftovers() -> list[str]:
            publishers, subscribers, services = client.get_system_state()
            return [
                name
                for entries in (publishers, subscribers, services)
                for name, callers in entries
                if "/quick_exit" in callers
            ]

        assert wait_until(lambda: not leftovers(), timeout=3.0), leftovers()
    finally:
        client.close()


def test_spec_records_behave_as_frozen_values() -> None:
    """idl.spec's records replaced frozen slotted dataclasses (start-up cost): same value semantics."""
    header = FieldType("std_msgs/Header")
    assert header == FieldType("std_msgs/Header", False, None)
    assert header != FieldType("std_msgs/Header", True, None)
    assert hash(header) == hash(FieldType("std_msgs/Header"))
    assert str(FieldType("uint8", True, 4)) == "uint8[4]"
    spec = MsgSpec(
        "pkg/M",
        fields=(Field("header", header, "Header"),),
        constants=(Constant("int32", "X", 1, "1"),),
    )
    assert spec.has_header and spec.dependencies == ("std_msgs/Header",)
    assert repr(FieldType("int8")) == "FieldType(base='int8', is_array=False, array_len=None)"
    with pytest.raises(AttributeError):
        spec.full_name = "other/M"  # type: ignore[misc]
    assert not hasattr(spec, "__dict__")
    assert pickle.loads(pickle.dumps(spec)) == spec
    assert {spec: 1}[MsgSpec("pkg/M", spec.fields, spec.constants)] == 1


def test_the_lazy_hook_imports_nothing_for_other_modules() -> None:
    """The finder sits last on sys.meta_path and is asked about every missing module (``nt`` while
    pathlib loads...): importing the loader from there deadlocked against init_node's helper thread."""
    code = (
        "import sys, rospy\n"
        "from ninjemys.idl.hook import LazyInterfaceFinder\n"
        "finder = LazyInterfaceFinder()\n"
        "assert finder.find_spec('nt') is None and finder.find_spec('no_such_pkg.msg') is None\n"
        "assert finder.find_spec('os.path.msg') is None\n"
        "assert 'ninjemys.idl.loader' not in sys.modules\n"
        "assert finder.find_spec('std_msgs.msg') is not None\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=_env(), capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr


def test_logging_while_init_node_helper_loads_classes_never_hangs(master: MasterProcess) -> None:
    """The first log line imports pathlib on the main thread while the helper imports the loader."""
    code = (
        "import rospy\n"
        "rospy.init_node('log_race', anonymous=True)\n"
        "for i in range(300):\n"
        "    rospy.loginfo('line %d', i)\n"
    )
    for _ in range(4):
        out = subprocess.run(
            [sys.executable, "-c", code],
            env=_env(master.uri),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=30,
        )
        assert out.returncode == 0, out.stderr
