"""Finding definitions: shipped packages, ROS_PACKAGE_PATH, workspaces; lazy modules; the import hook."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from idl_fixtures import FIXTURE_SRC

from ninjemys.errors import TypeNotFoundError
from ninjemys.idl import loader, search


def _run(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    full_env = {**os.environ, **env}
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=full_env,
        capture_output=True,
        text=True,
        timeout=60,
    )


def test_shipped_stub_modules_import_lazily() -> None:
    done = _run(
        """
        import sys
        from std_msgs.msg import String
        from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse
        from geometry_msgs.msg import Twist
        import std_msgs.msg as m
        assert String._type == "std_msgs/String" and Twist._type == "geometry_msgs/Twist"
        assert Trigger._request_class is TriggerRequest and Trigger._response_class is TriggerResponse
        assert "Header" in dir(m) and "String" in m.__all__
        try:
            from std_msgs.msg import NoSuchType
        except ImportError as exc:
            print("import-error", exc)
        print("numpy" in sys.modules)
        """
    )
    assert done.returncode == 0, done.stderr
    assert "import-error" in done.stdout and "NoSuchType" in done.stdout
    assert done.stdout.strip().endswith("False")  # generating classes does not import numpy


def test_user_package_on_ros_package_path_via_import_hook() -> None:
    done = _run(
        """
        from ninjemys.idl.loader import install_import_hook
        install_import_hook()
        install_import_hook()  # idempotent
        from h1_test_msgs.msg import Inner, CountAction, CountGoal
        from h1_test_msgs.srv import Compute, ComputeRequest
        print(Inner._type, CountGoal._type, Compute._type, ComputeRequest._type)
        print(Inner(name="x").name)
        """,
        ROS_PACKAGE_PATH=str(FIXTURE_SRC),
    )
    assert done.returncode == 0, done.stderr
    assert (
        "h1_test_msgs/Inner h1_test_msgs/CountGoal h1_test_msgs/Compute h1_test_msgs/ComputeRequest"
        in done.stdout
    )


def test_import_hook_leaves_unknown_modules_alone() -> None:
    done = _run(
        """
        from ninjemys.idl.loader import install_import_hook
        install_import_hook()
        try:
            import h1_no_such_pkg.msg
        except ModuleNotFoundError:
            print("not found")
        """,
        ROS_PACKAGE_PATH=str(FIXTURE_SRC),
    )
    assert done.stdout.strip() == "not found", done.stderr


def test_unknown_package_error_names_what_was_searched(fixture_path: Path) -> None:
    with pytest.raises(TypeNotFoundError) as info:
        loader.get_message_class("h1_missing_pkg/Thing")
    text = str(info.value)
    assert "h1_missing_pkg" in text and str(fixture_path) in text and str(search.SHIPPED_ROOT) in text


def test_unknown_type_in_known_package_names_the_package_path(fixture_path: Path) -> None:
    with pytest.raises(TypeNotFoundError, match=r"h1_test_msgs/Nope.*msg/Nope\.msg"):
        loader.get_message_class("h1_test_msgs/Nope")
    with pytest.raises(TypeNotFoundError):
        loader.get_service_class("h1_test_msgs/Nope")
    with pytest.raises(TypeNotFoundError, match="invalid"):
        loader.get_message_class("not a type")


def test_package_scan_rules(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "a" / "deep" / "pkg_one" / "msg").mkdir(parents=True)
    (tmp_path / "a" / "deep" / "pkg_one" / "package.xml").write_text(
        "<package><name>h1_pkg_one</name></package>"
    )
    (tmp_path / "a" / "deep" / "pkg_one" / "msg" / "M.msg").write_text("int32 x\n")
    # a package inside a package is not searched (rospack stops at package.xml)
    (tmp_path / "a" / "deep" / "pkg_one" / "inner").mkdir()
    (tmp_path / "a" / "deep" / "pkg_one" / "inner" / "package.xml").write_text(
        "<package><name>h1_hidden</name></package>"
    )
    (tmp_path / "ignored").mkdir()
    (tmp_path / "ignored" / "CATKIN_IGNORE").write_text("")
    (tmp_path / "ignored" / "p").mkdir()
    (tmp_path / "ignored" / "p" / "package.xml").write_text("<package><name>h1_ignored</name></package>")
    prefix = tmp_path / "install"
    (prefix / "share" / "h1_installed" / "msg").mkdir(parents=True)
    (prefix / "share" / "h1_installed" / "package.xml").write_text(
        "<package><name>h1_installed</name></package>"
    )
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "a") + os.pathsep + str(tmp_path / "ignored"))
    monkeypatch.setenv("CMAKE_PREFIX_PATH", str(prefix))
    found = search.packages()
    assert found["h1_pkg_one"].origin == "ROS_PACKAGE_PATH"
    assert found["h1_installed"].origin == "CMAKE_PREFIX_PATH"
    assert "h1_hidden" not in found and "h1_ignored" not in found
    assert list(found)[0] in os.listdir(search.SHIPPED_ROOT)  # shipped first
    assert loader.get_message_class("h1_pkg_one/M")(x=3).x == 3


def test_package_module_hooks_contract() -> None:
    getattr_, dir_ = loader.package_module_hooks("turtlesim.srv")
    assert "Spawn" in dir_() and "SpawnRequest" in dir_()
    assert getattr_("Spawn")._type == "turtlesim/Spawn"
    assert getattr_("SpawnResponse")._type == "turtlesim/SpawnResponse"
    with pytest.raises(AttributeError):
        getattr_("Nothing")
    with pytest.raises(ValueError):
        loader.package_module_hooks("turtlesim")


def test_pkg_msg_type_spelling_is_accepted() -> None:
    assert loader.get_message_class("std_msgs/msg/String") is loader.get_message_class("std_msgs/String")
    assert loader.get_message_class("Header")._type == "std_msgs/Header"
