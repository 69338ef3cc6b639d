"""The import surface of the shipped packages: ``from <pkg>.msg import T`` / ``from <pkg>.srv import S``.

Each shipped package has a lazy stub (``src/<pkg>/msg/__init__.py``): importing it is free, looking a
name up generates the class. Every shipped type must be reachable that way, ``dir()`` must list it (tab
completion, ``from pkg.msg import *``), and the class must be the one the loader hands out.
"""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest
from iface_inventory import SHIPPED_PACKAGES, inventory, package_of

from ninjemys.idl.loader import get_message_class, get_service_class

INV = inventory()


@pytest.mark.parametrize("pkg", SHIPPED_PACKAGES)
def test_every_type_is_importable_from_its_package(pkg: str) -> None:
    messages = [t for t in INV.messages if package_of(t) == pkg]
    services = [t for t in INV.services if package_of(t) == pkg]
    if messages:
        module = importlib.import_module(f"{pkg}.msg")
        assert {t.split("/")[1] for t in messages} <= set(dir(module))
        for type_name in messages:
            assert getattr(module, type_name.split("/")[1]) is get_message_class(type_name)
    if services:
        module = importlib.import_module(f"{pkg}.srv")
        names = set(dir(module))
        for type_name in services:
            short = type_name.split("/")[1]
            assert {short, f"{short}Request", f"{short}Response"} <= names
            srv = getattr(module, short)
            assert srv is get_service_class(type_name)
            assert getattr(module, f"{short}Request") is srv._request_class
            assert getattr(module, f"{short}Response") is srv._response_class


def test_unknown_name_is_an_attribute_error_naming_the_package() -> None:
    module = importlib.import_module("geometry_msgs.msg")
    with pytest.raises(AttributeError, match="geometry_msgs"):
        module.NoSuchType  # noqa: B018


def test_importing_a_package_generates_nothing_until_a_name_is_used() -> None:
    """No work at import: a fresh interpreter importing every stub reads no definition file."""
    script = (
        "import sys\n"
        "opened = []\n"
        "def hook(event, args):\n"
        "    if event == 'open' and str(args[0]).endswith(('.msg', '.srv', '.action')):\n"
        "        opened.append(str(args[0]))\n"
        "sys.addaudithook(hook)\n"
        f"for pkg in {list(SHIPPED_PACKAGES)!r}:\n"
        "    __import__(pkg)\n"
        "import std_msgs.msg, sensor_msgs.msg, std_srvs.srv\n"
        "at_import = len(opened)\n"
        "from std_msgs.msg import String\n"
        "from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse\n"
        "from geometry_msgs.msg import Twist\n"
        "assert String(data='x').data == 'x' and Twist().linear.x == 0.0\n"
        "assert TriggerResponse(success=True).success is True and Trigger._request_class is TriggerRequest\n"
        "print(at_import, len(opened) > 0)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0", "True"]
