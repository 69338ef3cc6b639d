"""dynamic_reconfigure on Debian's own generated TestConfig (nested groups, an enum, every type),
printed as JSON (run under either interpreter, ROS_MASTER_URI set): the encoding functions' messages
(as serialized bytes) and dicts, then a Server and a Client in one node: what update_configuration
returns (clamped values included), what the server callback receives, and the client's descriptions."""

import io
import json
import threading
import time
import types

import rospy
from dynamic_reconfigure import encoding
from dynamic_reconfigure.client import Client
from dynamic_reconfigure.server import Server

SOURCE = "/usr/lib/python3/dist-packages/dynamic_reconfigure/cfg/TestConfig.py"
cfg = types.ModuleType("TestConfig")
with open(SOURCE) as f:
    exec(compile(f.read(), SOURCE, "exec"), cfg.__dict__)


def wire(msg):
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue().hex()


def plain(x):
    """A JSON-able copy; infinities as strings."""
    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in sorted(x.items())}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, float) and x in (float("inf"), float("-inf")):
        return repr(x)
    return x


out = {"encoding": {}, "live": {}}
descr = encoding.encode_description(cfg)
out["encoding"]["description_wire"] = wire(descr)
out["encoding"]["defaults_wire"] = wire(encoding.encode_config(cfg.defaults))
out["encoding"]["decode_description"] = plain(encoding.decode_description(descr))
out["encoding"]["tree"] = plain(encoding.get_tree(descr))
out["encoding"]["initial"] = plain(
    encoding.initial_config(encoding.encode_config(cfg.defaults), cfg.config_description)
)
out["encoding"]["decode_config"] = plain(encoding.decode_config(encoding.encode_config(cfg.defaults)))
out["encoding"]["extract"] = [p["name"] for p in encoding.extract_params(cfg.config_description)]
out["encoding"]["group_dict"] = plain(encoding.group_dict(descr.groups[2]))

rospy.init_node("parity_dynreconf_peer")
received = []


def callback(config, level):
    received.append([plain({k: v for k, v in config.items() if k != "groups"}), level])
    config["str_"] = config["str_"].upper()
    return config


server = Server(cfg, callback)
seen = []
ready = threading.Event()


def on_config(config):
    seen.append(config is not None)
    ready.set()


client = Client("parity_dynreconf_peer", timeout=10, config_callback=on_config)
ready.wait(10.0)
out["live"]["first"] = plain({k: v for k, v in client.get_configuration(timeout=10).items() if k != "groups"})
changes = [
    {"int_": 3, "double_": 2.5, "str_": "abc", "bool_": True},
    {"int_": 1000, "double_": -7.0, "int_enum_": 2},
    {"group1_int": 9, "deep_var_bool": False},
]
for i, change in enumerate(changes):
    result = client.update_configuration(change)
    out["live"][f"update_{i}"] = plain({k: v for k, v in result.items() if k != "groups"})


def outcome(fn, *args, **kwargs):
    try:
        return ["ok", plain(fn(*args, **kwargs))]
    except Exception as exc:
        bases = [c.__name__ for c in type(exc).__mro__ if c.__name__ not in ("NinjemysError", "object")]
        return ["raise", bases, str(exc)]


def update(change):
    result = client.update_configuration(change)
    return {k: v for k, v in result.items() if k != "groups"}


out["live"]["unknown_name"] = outcome(update, {"no_such_param": 1})
out["live"]["bad_int"] = outcome(update, {"int_": "abc"})
out["live"]["bad_bool"] = outcome(update, {"bool_": "maybe"})
out["live"]["int_from_float"] = outcome(update, {"int_": 2.7})
out["live"]["double_from_int"] = outcome(update, {"double_": 4})
out["live"]["bool_from_str"] = outcome(update, {"bool_": "True"})
out["live"]["str_from_int"] = outcome(update, {"str_": 5})
out["live"]["no_server"] = outcome(Client, "no_such_server", timeout=0.3)
server_side = server.update_configuration({"int_": 4, "double_": 100.0, "str_": "srv"})
out["live"]["server_update"] = plain({k: v for k, v in server_side.items() if k != "groups"})
deadline = time.time() + 10.0  # the update reaches the client on its own thread
while client.get_configuration(timeout=10)["int_"] != 4 and time.time() < deadline:
    time.sleep(0.01)
out["live"]["server_update_seen"] = plain(
    {k: v for k, v in client.get_configuration(timeout=10).items() if k in ("int_", "double_", "str_")}
)
out["live"]["groups"] = plain(client.get_configuration(timeout=10)["groups"])
out["live"]["param_names"] = [p["name"] for p in client.get_parameter_descriptions(timeout=10)]
out["live"]["param_first"] = plain(client.get_parameter_descriptions(timeout=10)[0])
out["live"]["group_names"] = sorted(client.get_group_descriptions(timeout=10)["groups"])
out["live"]["received"] = received
out["live"]["callback_seen"] = bool(seen) and all(seen)
print(json.dumps(out))
client.close()
rospy.signal_shutdown("done")
