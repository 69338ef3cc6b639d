"""``rosrun dynamic_reconfigure dynparam list|get|set|set_from_parameters|load|dump``, as ROS 1's.

Same command line (optparse, ``-t/--timeout``), same output: ``get`` prints the configuration dict,
``dump`` writes it with PyYAML (the ``!!python/object/new:dynamic_reconfigure.encoding.Config`` form,
so dumps load in either direction), ``load`` reads such files. Where ROS 1 would print a traceback
(a timeout, no master) this prints one line on stderr and exits 1.
"""

from __future__ import annotations

import optparse
import sys
from collections.abc import Iterator
from typing import Any

from ninjemys.dynamic_reconfigure.client import ReconfigureClient, reconfigure_servers
from ninjemys.dynamic_reconfigure.errors import (
    DynamicReconfigureCallbackException,
    DynamicReconfigureParameterException,
)
from ninjemys.errors import MasterUnreachable, NinjemysError, ParameterError, ServiceError, TimeoutError_

NAME = "dynparam"

USAGE = """dynparam is a command-line tool for getting, setting, and
deleting parameters of a dynamically configurable node.

Commands:
\tdynparam set                  configure node
\tdynparam set_from_parameters  copy configuration from parameter server
\tdynparam get                  get node configuration
\tdynparam load                 load configuration from file
\tdynparam dump                 dump configuration to file
\tdynparam list                 list configurable nodes

Type dynparam <command> -h for more detailed usage, e.g. 'dynparam get -h'
"""

SET_FROM_PARAMETERS_USAGE = """Usage: %prog set_from_parameters [options] node

Example command line:
  dynparam set_from_parameters wge100_camera _camera_url:=foo

Example launch file:
  <launch>
    <node name="$(anon adjust-wge100_camera)" pkg="dynamic_reconfigure" type="dynparam" args="set_from_parameters wge100_camera">
      <param name="camera_url" value="foo" />
      <param name="brightness" value="58" />
    </node>
  </launch>"""

SET_USAGE = """Usage: %prog set [options] node parameter value
   or: %prog set [options] node values

Examples:
  dynparam set wge100_camera camera_url foo
  dynparam set wge100_camera "{'camera_url':'foo', 'brightness':58}" """

_SET_ARGS_ERROR = (
    "invalid arguments. Please specify either a node name, parameter name and parameter value, "
    "or a node name and a YAML dictionary"
)


class _Session:
    """The command's node (``dynparam`` anonymous, with the remappings and ``_param:=`` of argv)."""

    def __init__(self, argv: list[str]) -> None:
        from ninjemys.node.cli_args import parse_args

        self.args = parse_args([NAME, *argv])
        self.node: Any = None

    @property
    def myargv(self) -> list[str]:
        return self.args.argv

    def connect(self) -> Any:
        from ninjemys.node import Node

        self.node = Node(
            self.args.node_name(NAME, anonymous=True),
            namespace=self.args.namespace,
            remappings=self.args.remappings,
            master_uri=self.args.master_uri,
            params=self.args.private_params,
        )
        return self.node

    def close(self) -> None:
        if self.node is not None:
            self.node.shutdown("dynparam done")


def _parser(usage: str) -> optparse.OptionParser:
    parser = optparse.OptionParser(usage=usage, prog=NAME)
    parser.add_option("-t", "--timeout", action="store", type="float", default=None, help="timeout in secs")
    return parser


def _client(session: _Session, name: str, timeout: float | None) -> ReconfigureClient:
    return ReconfigureClient(session.node, name, timeout=timeout)


def _get(session: _Session, name: str, timeout: float | None) -> Any:
    client = _client(session, name, timeout)
    return client.get_configuration(timeout=timeout)


def _set(session: _Session, name: str, params: dict[str, Any], timeout: float | None) -> None:
    client = _client(session, name, timeout)
    try:
        client.update_configuration(params)
    except DynamicReconfigureParameterException as exc:
        print("error updating parameters: " + str(exc))


def do_list(session: _Session) -> None:
    session.connect()
    for name in reconfigure_servers(session.node):
        print(name)


def do_set_from_parameters(session: _Session) -> None:
    parser = _parser(SET_FROM_PARAMETERS_USAGE)
    options, args = parser.parse_args(session.myargv[2:])
    if not args:
        parser.error("invalid arguments. Please specify a node name")
    elif len(args) > 1:
        parser.error("too many arguments")
    session.connect()
    try:
        params = session.node.get_param("~")
    except ParameterError:
        print("error updating parameters: no parameters found on parameter server", file=sys.stderr)
        return
    _set(session, args[0], params, options.timeout)


def do_set(session: _Session) -> None:
    import yaml

    args: list[str] = []
    options_args: list[str] = []
    for arg in session.myargv[2:]:
        if arg.startswith("-") and not (len(arg) > 1 and arg[1].isdigit()):
            options_args.append(arg)
        else:
            args.append(arg)
    parser = _parser(SET_USAGE)
    options, _ = parser.parse_args(options_args)
    if len(args) > 3:
        parser.error("too many arguments")
    elif len(args) < 2:
        parser.error(_SET_ARGS_ERROR)
    node = args[0]
    if len(args) == 2:
        try:
            values = yaml.load(args[1], Loader=yaml.SafeLoader)
        except yaml.YAMLError:
            values = None
        if type(values) is not dict:
            parser.error(_SET_ARGS_ERROR)
    else:
        values = {args[1]: args[2]}
    session.connect()
    try:
        _set(session, node, values, options.timeout)
    except (ServiceError, DynamicReconfigureCallbackException, TimeoutError_):
        print(f"couldn't set parameters at node {node}")


def do_get(session: _Session) -> None:
    parser = _parser("Usage: %prog get [options] node")
    options, args = parser.parse_args(session.myargv[2:])
    if not args:
        parser.error("invalid arguments. Please specify a node name")
    elif len(args) > 1:
        parser.error("too many arguments")
    session.connect()
    params = _get(session, args[0], options.timeout)
    if params is not None:
        print(params)


def do_load(session: _Session) -> None:
    import yaml

    parser = _parser("Usage: %prog load [options] node file")
    options, args = parser.parse_args(session.myargv[2:])
    if not args:
        parser.error("invalid arguments. Please specify a node name")
    elif len(args) == 1:
        parser.error("invalid arguments. Please specify an input file")
    elif len(args) > 2:
        parser.error("too many arguments")
    node, path = args
    import dynamic_reconfigure.encoding  # noqa: F401  (the Config class dump files name)

    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        params: dict[str, Any] = {}
        for doc in yaml.load_all(text, Loader=_DumpLoader):
            params.update(doc or {})
    except OSError as exc:
        raise NinjemysError(f"cannot read {path}: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        raise NinjemysError(f"{path}: not a dynparam dump: {str(exc).splitlines()[0]}") from None
    session.connect()
    _set(session, node, params, options.timeout)


def do_dump(session: _Session) -> None:
    import yaml

    parser = _parser("Usage: %prog dump [options] node file")
    options, args = parser.parse_args(session.myargv[2:])
    if not args:
        parser.error("invalid arguments. Please specify a node name")
    elif len(args) == 1:
        parser.error("invalid arguments. Please specify an output file")
    elif len(args) > 2:
        parser.error("too many arguments")
    node, path = args
    session.connect()
    params = _get(session, node, options.timeout)
    if params is not None:
        # a course's hard-coded path (/home/<author>/...) is one line naming the file, not a traceback
        try:
            with open(path, "w", encoding="utf-8") as f:
                yaml.dump(params, f)
        except OSError as exc:
            raise NinjemysError(f"cannot write {path}: {exc.strerror}") from None
        return
    print(f"couldn't get parameters from node {node}")


def _dump_loader() -> type:
    """A YAML loader that builds ``dynamic_reconfigure.encoding.Config`` (and nothing else unsafe)."""
    import yaml

    from ninjemys.dynamic_reconfigure.encoding import Config

    class Loader(yaml.SafeLoader):
        pass

    def config(loader: yaml.SafeLoader, suffix: str, node: yaml.Node) -> Iterator[Config]:
        if suffix != "dynamic_reconfigure.encoding.Config" or not isinstance(node, yaml.MappingNode):
            raise yaml.constructor.ConstructorError(None, None, f"unexpected tag {suffix}", node.start_mark)
        result = Config()
        yield result
        fields = loader.construct_mapping(node, deep=True)
        result.update(fields.get("dictitems", {}))

    Loader.add_multi_constructor("tag:yaml.org,2002:python/object/new:", config)
    return Loader


_DumpLoader: Any = None

COMMANDS = {
    "list": do_list,
    "set_from_parameters": do_set_from_parameters,
    "set": do_set,
    "get": do_get,
    "load": do_load,
    "dump": do_dump,
}


def main(argv: list[str] | None = None) -> int:
    global _DumpLoader
    argv = sys.argv[1:] if argv is None else argv
    session = _Session(argv)
    myargv = session.myargv
    if len(myargv) == 1 or myargv[1] not in COMMANDS:
        print(USAGE)
        return 1
    if myargv[1] == "load":
        _DumpLoader = _dump_loader()
    try:
        COMMANDS[myargv[1]](session)
    except MasterUnreachable:
        print("ERROR: Unable to communicate with master!", file=sys.stderr)
        return 1
    except TimeoutError_ as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    except (NinjemysError, DynamicReconfigureCallbackException) as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        session.close()
    return 0
