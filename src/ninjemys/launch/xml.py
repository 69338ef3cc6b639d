"""roslaunch XML -> :class:`~ninjemys.launch.plan.LaunchPlan`, with roslaunch's scoping rules.

Scoping follows ROS 1 exactly because users depend on its corners:

* ``<group>`` and ``<node>`` open a child scope: args declared inside stay inside, remaps and envs
  are inherited, ``~private`` params declared in a group apply to the nodes that follow in it;
* ``<include>`` sees only the args passed to it (``<arg name value>`` children, or all of the
  parent's with ``pass_all_args``); passing an arg the included file does not declare is an error;
* ``$(arg x)`` of an arg without value is reported as ``arg 'x' is not set`` with file and line;
* unknown tags and attributes are warnings (``plan.warnings``), as in ROS 1, not errors.

Every error is a LaunchError that starts with ``file:line:``.
"""

from __future__ import annotations

import copy
import os
import shlex
import subprocess
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ninjemys.commands import with_our_commands
from ninjemys.errors import LaunchError, NinjemysError
from ninjemys.launch.dom import Element, parse_xml
from ninjemys.launch.plan import LaunchPlan, Machine, NodeSpec, SetupCommand
from ninjemys.launch.substitutions import ArgNotSet, SubstitutionContext, resolve
from ninjemys.launch.values import convert_value
from ninjemys.names import (
    canonicalize_name,
    get_ros_namespace,
    is_legal_name,
    is_private,
    load_mappings,
    make_global_ns,
    ns_join,
)
from ninjemys.paramyaml import ParamYamlError, load_yaml

if TYPE_CHECKING:
    from ninjemys.packages.discovery import PackageIndex

NODE_ATTRS = (
    "pkg",
    "type",
    "machine",
    "name",
    "args",
    "output",
    "respawn",
    "respawn_delay",
    "cwd",
    "ns",
    "clear_params",
    "launch-prefix",
    "required",
    "sigint_timeout",
)
TEST_ATTRS = (*NODE_ATTRS, "test-name", "time-limit", "retry")
PARAM_ATTRS = ("name", "value", "type", "textfile", "binfile", "command")
ROSPARAM_ATTRS = ("command", "ns", "file", "param", "subst_value")
ARG_ATTRS = ("name", "value", "default", "doc")
MACHINE_ATTRS = ("name", "address", "env-loader", "ssh-port", "user", "password", "default", "timeout")
INCLUDE_ATTRS = ("file", "ns", "clear_params", "pass_all_args")
GROUP_ATTRS = ("ns", "clear_params")
REMAP_ATTRS = ("from", "to")
ENV_ATTRS = ("name", "value")


@dataclass
class _Param:
    key: str
    value: Any


@dataclass
class _Scope:
    """One loader context (roslaunch's LoaderContext): namespace, args, private params, remaps, env."""

    ns: str
    filename: str
    args: dict[str, str]
    anons: dict[str, str]
    arg_names: list[str] = field(default_factory=list)
    params: list[_Param] = field(default_factory=list)
    env_args: list[tuple[str, str]] = field(default_factory=list)
    own_remaps: list[tuple[str, str]] = field(default_factory=list)
    parent: _Scope | None = None
    #: for an <include>: the args being passed (None outside the include's own arg children)
    include_args: dict[str, str] | None = None
    passed: list[str] = field(default_factory=list)
    pass_all_args: bool = False

    def child(self, ns: str | None) -> _Scope:
        if ns:
            child_ns = ns if ns.startswith("/") else ("~" if ns == "~" else ns_join(self.ns, ns))
        else:
            child_ns = self.ns
        return _Scope(
            ns=make_global_ns(child_ns) if child_ns != "~" else child_ns,
            filename=self.filename,
            args=copy.deepcopy(self.args),
            anons=dict(self.anons),
            arg_names=list(self.arg_names),
            params=self.params,
            env_args=list(self.env_args),
            parent=self,
            include_args=self.include_args,
        )

    def remaps(self) -> list[tuple[str, str]]:
        if self.parent is None:
            return list(self.own_remaps)
        inherited = [r for r in self.parent.remaps() if not any(o[0] == r[0] for o in self.own_remaps)]
        return inherited + self.own_remaps

    def add_remap(self, src: str, dst: str) -> None:
        src, dst = canonicalize_name(src), canonicalize_name(dst)
        if not src or not dst:
            raise LaunchError("remap from/to attributes cannot be empty")
        for name in (src, dst):
            if not is_legal_name(name):
                raise LaunchError(f"remap [{name}] is not a valid ROS name")
        self.own_remaps = [r for r in self.own_remaps if r[0] != src]
        self.own_remaps.append((src, dst))

    def add_private_param(self, param: _Param) -> None:
        self.params[:] = [p for p in self.params if p.key != param.key]
        self.params.append(param)

    def add_arg(self, name: str, value: str | None, default: str | None) -> None:
        if name in self.arg_names:
            if not self.pass_all_args:
                raise LaunchError(f"arg '{name}' has already been declared")
        else:
            self.arg_names.append(name)
        target = self.args if self.include_args is None else self.include_args
        if value is not None:
            if name in target and not self.pass_all_args:
                raise LaunchError(f"cannot override arg '{name}', which has already been set")
            target[name] = value
        elif default is not None and name not in target:
            target[name] = default


class _Loader:
    def __init__(self, plan: LaunchPlan, env: Mapping[str, str], args_only: bool = False) -> None:
        self.plan = plan
        self.args_only = args_only
        self.env = env
        self.anons: dict[str, str] = {}
        self._index: PackageIndex | None = None

    # -- helpers ---------------------------------------------------------------------------------
    def _find(self, pkg: str) -> str:
        if self._index is None:
            from ninjemys.packages.discovery import PackageIndex

            self._index = PackageIndex.from_environment(self.env)
        try:
            return str(self._index.find(pkg).path)
        except NinjemysError:
            # ROS 1's words ("Resource not found" and the package path searched), after file:line
            from ninjemys.packages.discovery import package_path_dirs, underlay_dirs

            paths = [*package_path_dirs(self.env), *underlay_dirs()]
            where = "".join(f"\nROS path [{i}]={path}" for i, path in enumerate(paths))
            raise LaunchError(f"$(find {pkg}): Resource not found: {pkg}{where}") from None

    def sub(self, text: str | None, scope: _Scope, el: Element) -> str | None:
        if text is None or "$" not in text:
            return text
        ctx = SubstitutionContext(
            args=scope.args, filename=scope.filename, anons=scope.anons, env=self.env, find=self._find
        )
        try:
            return resolve(text, ctx)
        except ArgNotSet:
            raise
        except LaunchError as exc:
            raise LaunchError(f"{scope.filename}:{el.line}: {exc}") from None

    def opt(self, el: Element, scope: _Scope, name: str) -> str | None:
        return self.sub(el.attrs.get(name), scope, el)

    def req(self, el: Element, scope: _Scope, name: str) -> str:
        if name not in el.attrs:
            raise LaunchError(
                f"{scope.filename}:{el.line}: <{el.tag}> tag is missing required attribute: '{name}'"
            )
        value = self.sub(el.attrs[name], scope, el)
        assert value is not None
        return value

    def err(self, el: Element, scope: _Scope, message: str) -> LaunchError:
        return LaunchError(f"{scope.filename}:{el.line}: {message}")

    def check_attrs(self, el: Element, scope: _Scope, allowed: tuple[str, ...]) -> None:
        for attr in el.attrs:
            if attr not in allowed and attr not in ("if", "unless"):
                self.plan.warnings.append(
                    f"[{scope.filename}:{el.line}] unknown <{el.tag}> attribute '{attr}'"
                )

    def bool_attr(self, value: str | None, default: bool, label: str, el: Element, scope: _Scope) -> bool:
        if value is None:
            return default
        if value.lower() == "true":
            return True
        if value.lower() == "false":
            return False
        raise self.err(el, scope, f"invalid bool value for {label}: {value!r}")

    def float_attr(self, value: str | None, default: float, label: str, el: Element, scope: _Scope) -> float:
        if value is None:
            return default
        try:
            return float(value)
        except ValueError:
            raise self.err(el, scope, f"invalid float value for {label}: {value!r}") from None

    def included(self, el: Element, scope: _Scope) -> bool:
        """The tag's if/unless verdict."""
        if_val, unless_val = self.opt(el, scope, "if"), self.opt(el, scope, "unless")
        if if_val is not None and unless_val is not None:
            raise self.err(el, scope, "cannot set both 'if' and 'unless' on the same tag")
        try:
            if if_val is not None:
                return bool(convert_value(if_val, "bool"))
            if unless_val is not None:
                return not convert_value(unless_val, "bool")
        except LaunchError as exc:
            raise self.err(el, scope, f"if/unless: {exc}") from None
        return True

    # -- tags ------------------------------------------------------------------------------------
    def load_file(self, filename: str, scope: _Scope) -> None:
        try:
            data = Path(filename).read_bytes()
        except OSError as exc:
            raise LaunchError(f"{filename}: cannot read launch file: {exc.strerror}") from None
        root = parse_xml(data, filename)
        self.plan.files.append(filename)
        self.launch_tag(root, scope)

    def launch_tag(self, root: Element, scope: _Scope) -> None:
        deprecated = root.attrs.get("deprecated")
        if deprecated:
            self.plan.warnings.append(f"[{scope.filename}] DEPRECATED: {deprecated}")
        self.children(root.children, scope, default_machine=None)

    def children(
        self, elements: list[Element], scope: _Scope, default_machine: Machine | None
    ) -> Machine | None:
        for el in elements:
            try:
                default_machine = self.element(el, scope, default_machine)
            except ArgNotSet as exc:
                raise LaunchError(
                    f"{scope.filename}:{el.line}: arg '{exc.name}' is not set "
                    f"(pass {exc.name}:=VALUE or give the <arg> a default)"
                ) from None
        return default_machine

    def element(self, el: Element, scope: _Scope, default_machine: Machine | None) -> Machine | None:
        tag = el.tag
        if tag == "master":
            self.plan.warnings.append("ignoring defunct <master /> tag")
            return default_machine
        if tag not in (
            "arg",
            "group",
            "node",
            "test",
            "param",
            "remap",
            "machine",
            "rosparam",
            "include",
            "env",
        ):
            self.plan.warnings.append(f"[{scope.filename}:{el.line}] unrecognized tag {tag}")
            return default_machine
        if self.args_only and tag != "arg":
            return default_machine
        if not self.included(el, scope):
            return default_machine
        if tag == "arg":
            self.arg_tag(el, scope)
        elif tag == "group":
            self.check_attrs(el, scope, GROUP_ATTRS)
            child = self.ns_clear_params(el, scope)
            child.params = list(child.params)
            default_machine = self.children(el.children, child, default_machine)
        elif tag in ("node", "test"):
            self.node_tag(el, scope, default_machine, is_test=tag == "test")
        elif tag == "param":
            self.param_tag(el, scope)
        elif tag == "remap":
            self.check_attrs(el, scope, REMAP_ATTRS)
            try:
                scope.add_remap(self.req(el, scope, "from"), self.req(el, scope, "to"))
            except LaunchError as exc:
                if str(exc).startswith(scope.filename):
                    raise
                raise self.err(el, scope, f"Invalid <remap> tag: {exc}") from None
        elif tag == "machine":
            machine, is_default = self.machine_tag(el, scope)
            if is_default:
                default_machine = machine
            existing = self.plan.machines.get(machine.name)
            if existing is not None and existing != machine:
                raise self.err(
                    el, scope, f"Machine [{machine.name}] already added and does not match duplicate entry"
                )
            self.plan.machines[machine.name] = machine
        elif tag == "rosparam":
            self.rosparam_tag(el, scope)
        elif tag == "include":
            default_machine = self.include_tag(el, scope, default_machine)
        elif tag == "env":
            self.env_tag(el, scope)
        return default_machine

    def arg_tag(self, el: Element, scope: _Scope) -> None:
        self.check_attrs(el, scope, ARG_ATTRS)
        name = self.req(el, scope, "name")
        value, default = self.opt(el, scope, "value"), self.opt(el, scope, "default")
        if value is not None and default is not None:
            raise self.err(el, scope, "<arg> tag must have one and only one of value/default.")
        try:
            scope.add_arg(name, value=value, default=default)
        except LaunchError as exc:
            raise self.err(el, scope, str(exc)) from None
        if scope.parent is None and value is None:
            self.plan.arg_docs[name] = (self.opt(el, scope, "doc"), default)

    def ns_clear_params(
        self, el: Element, scope: _Scope, node_name: str | None = None, include_file: str | None = None
    ) -> _Scope:
        ns = None
        if "ns" in el.attrs:
            ns = self.opt(el, scope, "ns")
            if not ns:
                raise self.err(el, scope, f"<{el.tag}> tag has an empty 'ns' attribute")
        child = scope.child(ns)
        if include_file is not None:
            child.arg_names = []
            child.filename = include_file
            child.include_args = {}
        clear = self.opt(el, scope, "clear_params")
        if clear and self.bool_attr(clear, False, "clear_params", el, scope):
            if el.tag == "node":
                if not node_name:
                    raise self.err(el, scope, "<node> tag must have a 'name' attribute to use 'clear_params'")
                self.plan.clear_params.append(make_global_ns(ns_join(child.ns, node_name)))
            else:
                if not ns:
                    raise self.err(el, scope, "'ns' attribute must be set in order to use 'clear_params'")
                self.plan.clear_params.append(child.ns)
        return child

    def add_param(self, key: str, value: Any, el: Element, scope: _Scope, unroll: bool = False) -> None:
        """Set a global parameter.

        ``<rosparam>`` dictionaries unroll into one parameter per leaf; a ``<param type="yaml">``
        dictionary stays one parameter, as in ROS 1.
        """
        if not key:
            raise self.err(el, scope, "no parameter name specified")
        if unroll and key == "/" and not isinstance(value, dict):
            raise self.err(el, scope, "Cannot load non-dictionary types into global namespace '/'")
        if unroll and isinstance(value, dict):
            for k, v in value.items():
                self.add_param(ns_join(key, str(k)), v, el, scope, unroll=True)
            return
        parts = key.strip("/").split("/")
        for i in range(1, len(parts)):
            parent = "/" + "/".join(parts[:i])
            if parent in self.plan.params:
                self.plan.warnings.append(f"parameter [{key}] conflicts with parent parameter [{parent}]")
        self.plan.params[key] = value

    def param_value(self, el: Element, scope: _Scope, name: str, ptype: str) -> Any:
        value, textfile, binfile, command = (
            self.opt(el, scope, a) for a in ("value", "textfile", "binfile", "command")
        )
        given = [v for v in (value, textfile, binfile, command) if v is not None]
        if len(given) != 1:
            raise self.err(el, scope, "<param> tag must have one and only one of value/textfile/binfile.")
        try:
            if value is not None:
                return convert_value(value.strip(), ptype)
            if textfile is not None:
                try:
                    return convert_value(Path(textfile).read_text(encoding="utf-8"), ptype)
                except OSError as exc:
                    raise LaunchError(f"cannot read textfile [{textfile}]: {exc.strerror}") from None
            if binfile is not None:
                try:
                    return Path(binfile).read_bytes()
                except OSError as exc:
                    raise LaunchError(f"cannot read binfile [{binfile}]: {exc.strerror}") from None
            assert command is not None
            argv = shlex.split(command)
            try:
                proc = subprocess.run(
                    argv,
                    stdout=subprocess.PIPE,
                    check=False,
                    timeout=60,
                    env=with_our_commands(self.env),
                )
            except FileNotFoundError:
                raise LaunchError(
                    f"Cannot load command parameter [{name}]: no such command [{argv!r}]"
                ) from None
            except subprocess.TimeoutExpired:
                raise LaunchError(
                    f"Cannot load command parameter [{name}]: command [{command}] timed out"
                ) from None
            if proc.returncode != 0:
                raise LaunchError(
                    f"Cannot load command parameter [{name}]: command [{argv!r}] returned with code [{proc.returncode}]"
                )
            return convert_value(proc.stdout.decode("utf-8", errors="replace"), ptype)
        except LaunchError as exc:
            raise self.err(el, scope, f"Invalid <param> tag: {exc}") from None

    def param_tag(self, el: Element, scope: _Scope, force_local: bool = False) -> None:
        self.check_attrs(el, scope, PARAM_ATTRS)
        ptype = (el.attrs.get("type") or "auto").lower().strip()
        if "name" not in el.attrs:
            raise self.err(el, scope, "<param> tag is missing required attribute: 'name'")
        name = self.sub(el.attrs["name"].strip(), scope, el) or ""
        value = self.param_value(el, scope, name, ptype)
        if is_private(name) or force_local:
            scope.add_private_param(_Param(name, value))
        else:
            self.add_param(ns_join(scope.ns, name), value, el, scope)

    def rosparam_tag(self, el: Element, scope: _Scope) -> None:
        self.check_attrs(el, scope, ROSPARAM_ATTRS)
        cmd, ns, file, param, subst = (self.opt(el, scope, a) for a in ROSPARAM_ATTRS)
        subst_value = self.bool_attr(subst, False, "subst_value", el, scope)
        param = ns_join(ns or "", param or "")
        cmd = cmd or "load"
        if cmd not in ("load", "dump", "delete"):
            raise self.err(
                el, scope, "error loading <rosparam> tag: command must be 'load', 'dump', or 'delete'"
            )
        full = ns_join(scope.ns, param) if param else scope.ns
        if file is not None and cmd == "delete":
            raise self.err(
                el, scope, "error loading <rosparam> tag: 'file' attribute is invalid with 'delete' command."
            )
        if cmd in ("dump", "delete"):
            self.plan.setup_commands.append(SetupCommand(cmd, full, file))
            return
        text = el.text
        if file is not None:
            try:
                text = Path(file).read_text(encoding="utf-8")
            except OSError:
                raise self.err(
                    el, scope, f"error loading <rosparam> tag: file does not exist [{file}]"
                ) from None
        if subst_value:
            text = self.sub(text, scope, el) or ""
        try:
            data = load_yaml(text)
        except ParamYamlError as exc:
            where = f"file {file}" if file else "YAML block"
            raise self.err(
                el, scope, f"error loading <rosparam> tag: invalid YAML in {where}: {exc}"
            ) from None
        if data is None:
            data = {}
        if not param and not isinstance(data, dict):
            raise self.err(
                el,
                scope,
                "error loading <rosparam> tag: 'param' attribute must be set for non-dictionary values",
            )
        self.add_param(full, data, el, scope, unroll=True)

    def env_tag(self, el: Element, scope: _Scope) -> None:
        self.check_attrs(el, scope, ENV_ATTRS)
        name, value = self.req(el, scope, "name"), self.req(el, scope, "value")
        if not name:
            raise self.err(el, scope, "Invalid <env> tag: 'name' attribute must be non-empty")
        scope.env_args.append((name, value))

    def machine_tag(self, el: Element, scope: _Scope) -> tuple[Machine, bool]:
        scope = scope.child(None)
        if any(el.attrs.get(a) for a in ("ros-root", "ros-package-path", "ros-ip", "ros-hostname")):
            raise self.err(
                el, scope, "<machine>: ros-* attributes are not supported since ROS Fuerte; use env-loader"
            )
        self.check_attrs(el, scope, MACHINE_ATTRS)
        name, address = self.req(el, scope, "name"), self.req(el, scope, "address")
        env_loader, ssh_port, user, password, default, timeout = (
            self.opt(el, scope, a)
            for a in ("env-loader", "ssh-port", "user", "password", "default", "timeout")
        )
        try:
            port = int(ssh_port or "22")
        except ValueError:
            raise self.err(el, scope, f"invalid ssh-port [{ssh_port}]") from None
        default = (default or "false").lower()
        if default not in ("true", "false", "never"):
            raise self.err(el, scope, f"Invalid value for 'default': {default}")
        for child in el.children:
            if child.tag == "env":
                raise self.err(
                    child, scope, "<machine>: <env> tag is not supported since ROS Fuerte; use env-loader"
                )
            self.plan.warnings.append(f"unrecognized '{child.tag}' tag in <machine> tag")
        timeout_value = None
        if timeout is not None:
            timeout_value = self.float_attr(timeout, 0.0, "timeout", el, scope)
            if timeout_value <= 0:
                raise self.err(el, scope, f"'timeout' be a positive number: [{timeout}]")
        machine = Machine(
            name,
            address,
            env_loader=env_loader,
            ssh_port=port,
            user=user,
            password=password,
            assignable=default != "never",
            timeout=timeout_value,
            env_args=list(scope.env_args),
        )
        return machine, default == "true"

    def node_tag(self, el: Element, scope: _Scope, default_machine: Machine | None, is_test: bool) -> None:
        test_name = time_limit = retry = None
        if is_test:
            self.check_attrs(el, scope, TEST_ATTRS)
            for attr in ("respawn", "respawn_delay", "output"):
                if attr in el.attrs:
                    raise self.err(el, scope, f"<test> tags cannot have '{attr}' attribute")
            test_name = self.req(el, scope, "test-name")
            name = self.opt(el, scope, "name") or test_name
            tl = self.opt(el, scope, "time-limit")
            if tl:
                time_limit = self.float_attr(tl, 60.0, "time-limit", el, scope)
                if time_limit <= 0:
                    raise self.err(el, scope, "'time-limit' must be a positive number")
            rt = self.opt(el, scope, "retry")
            if rt:
                try:
                    retry = int(rt)
                except ValueError:
                    raise self.err(el, scope, f"'retry' must be a number: [{rt}]") from None
        else:
            self.check_attrs(el, scope, NODE_ATTRS)
            name = self.req(el, scope, "name")
        if not is_legal_name(name):
            self.plan.warnings.append(
                # ROS 1's lines (roslaunch then starts the node under that name), with the file:line
                f"[{scope.filename}:{el.line}] illegal <node> name '{name}'.\nhttp://ros.org/wiki/Names\n"
                "This will likely cause problems with other ROS tools."
            )
        child = self.ns_clear_params(el, scope, node_name=name)
        param_scope = child.child(name)
        param_scope.params = []
        pkg, node_type = self.req(el, scope, "pkg"), self.req(el, scope, "type")
        machine = self.opt(el, scope, "machine")
        if not machine and default_machine is not None:
            machine = default_machine.name
        output = self.opt(el, scope, "output")
        if output is not None and output not in ("log", "screen"):
            raise self.err(
                el, scope, f"Invalid <node> tag: output must be one of 'log', 'screen', not {output!r}"
            )
        cwd = self.opt(el, scope, "cwd")
        if cwd is not None and cwd.lower() not in ("ros-root", "ros_home", "node", "ros_home"):
            raise self.err(el, scope, f"Invalid <node> tag: cwd must be 'ROS_HOME' or 'node', not {cwd!r}")
        required = self.bool_attr(self.opt(el, scope, "required"), False, "required", el, scope)
        respawn = self.bool_attr(self.opt(el, scope, "respawn"), False, "respawn", el, scope)
        if required and respawn:
            raise self.err(el, scope, "Invalid <node> tag: respawn and required cannot both be set to true")
        respawn_delay = self.float_attr(self.opt(el, scope, "respawn_delay"), 0.0, "respawn_delay", el, scope)
        sigint = self.opt(el, scope, "sigint_timeout")
        sigint_timeout = (
            self.float_attr(sigint, 0.0, "sigint_timeout", el, scope) if sigint is not None else None
        )
        remap_scope = scope.child("")
        env_scope = scope.child("")
        for sub in el.children:
            tag = sub.tag.lower()
            if tag not in ("remap", "param", "rosparam", "env"):
                self.plan.warnings.append(
                    f"[{scope.filename}:{sub.line}] unrecognized '{sub.tag}' child tag in <{el.tag}>"
                )
                continue
            if not self.included(sub, scope if tag == "remap" else param_scope):
                continue
            if tag == "remap":
                self.check_attrs(sub, scope, REMAP_ATTRS)
                try:
                    remap_scope.add_remap(self.req(sub, scope, "from"), self.req(sub, scope, "to"))
                except LaunchError as exc:
                    if str(exc).startswith(scope.filename):
                        raise
                    raise self.err(sub, scope, f"Invalid <remap> tag: {exc}") from None
            elif tag == "param":
                self.param_tag(sub, param_scope, force_local=True)
            elif tag == "rosparam":
                self.rosparam_tag(sub, param_scope)
            else:
                self.env_tag(sub, env_scope)
        for p in [*scope.params, *param_scope.params]:
            key = p.key[1:] if is_private(p.key) else p.key
            self.add_param(canonicalize_name(param_scope.ns + key), p.value, el, scope)
        spec = NodeSpec(
            package=pkg,
            type=node_type,
            name=name,
            namespace=child.ns,
            args=self.opt(el, scope, "args") or "",
            machine_name=machine,
            respawn=respawn,
            respawn_delay=respawn_delay,
            required=required,
            remap_args=remap_scope.remaps(),
            env_args=env_scope.env_args,
            output=output,
            cwd=cwd,
            launch_prefix=self.opt(el, scope, "launch-prefix"),
            filename=scope.filename,
            sigint_timeout=sigint_timeout,
            is_test=is_test,
            test_name=test_name,
            time_limit=time_limit,
            retry=retry,
        )
        if name:
            resolved = spec.resolved_name
            if resolved in self.plan.node_names():
                raise self.err(
                    el,
                    scope,
                    f"roslaunch file contains multiple nodes named [{resolved}]. Please check all <node> 'name' "
                    "attributes to make sure they are unique. Also check that $(anon id) use different ids.",
                )
        (self.plan.tests if is_test else self.plan.nodes).append(spec)

    def include_tag(self, el: Element, scope: _Scope, default_machine: Machine | None) -> Machine | None:
        self.check_attrs(el, scope, INCLUDE_ATTRS)
        filename = self.req(el, scope, "file")
        if not os.path.isabs(filename) and not os.path.exists(filename):
            # ROS 1 resolves relative includes from the working directory; fall back to the including file's
            filename = os.path.join(os.path.dirname(os.path.abspath(scope.filename)), filename)
        pass_all = self.bool_attr(self.opt(el, scope, "pass_all_args"), False, "pass_all_args", el, scope)
        child = self.ns_clear_params(el, scope, include_file=filename)
        if pass_all:
            for name, value in scope.args.items():
                child.add_arg(name, value=value, default=None)
            child.pass_all_args = True
        child.filename = scope.filename  # the include's own <arg>/<env> resolve relative to the parent
        for sub in el.children:
            tag = sub.tag.lower()
            if tag == "env":
                if self.included(sub, child):
                    self.env_tag(sub, child)
            elif tag == "arg":
                if self.included(sub, child):
                    self.arg_tag(sub, child)
            else:
                self.plan.warnings.append(
                    f"[{scope.filename}:{sub.line}] unrecognized '{sub.tag}' tag in <include> tag"
                )
        child.filename = filename
        passed = child.include_args or {}
        missing = [a for a in child.arg_names if a not in passed]
        if missing:
            raise self.err(el, scope, f"include args must have declared values: {', '.join(missing)}")
        child.passed = list(passed)
        child.arg_names = []
        child.args = dict(passed)
        child.include_args = None
        if not Path(filename).is_file():
            raise self.err(el, scope, f"included file [{filename}] does not exist")
        try:
            data = Path(filename).read_bytes()
        except OSError as exc:
            raise self.err(el, scope, f"cannot read included file [{filename}]: {exc.strerror}") from None
        root = parse_xml(data, filename)
        self.plan.files.append(filename)
        deprecated = root.attrs.get("deprecated")
        if deprecated:
            self.plan.warnings.append(f"[{filename}] DEPRECATED: {deprecated}")
        default_machine = self.children(root.children, child, default_machine)
        if not pass_all:
            unused = [a for a in child.passed if a not in child.arg_names]
            if unused:
                raise self.err(el, scope, f"unused args [{', '.join(unused)}] for include of [{filename}]")
        return default_machine


def command_line_args(argv: list[str]) -> dict[str, str]:
    """The ``name:=value`` launch args of a roslaunch command line."""
    return {k: v for k, v in load_mappings(argv).items() if not k.startswith("__")}


def load_launch(
    files: Sequence[str | Path],
    argv: list[str] | None = None,
    env: Mapping[str, str] | None = None,
    xml_text: str | None = None,
    args_only: bool = False,
) -> LaunchPlan:
    """Parse launch files (and/or XML text from stdin) into one plan; ``argv`` holds ``arg:=value``."""
    env = os.environ if env is None else env
    argv = argv or []
    plan = LaunchPlan()
    loader = _Loader(plan, env, args_only=args_only)
    ns = get_ros_namespace(env=env, argv=argv)
    sources: list[tuple[str, bytes | None]] = [(str(f), None) for f in files]
    if xml_text is not None:
        sources.append(("string", xml_text.encode("utf-8")))
    for filename, data in sources:
        scope = _Scope(ns=ns, filename=filename, args=command_line_args(argv), anons=loader.anons)
        if data is None:
            loader.load_file(filename, scope)
        else:
            root = parse_xml(data, filename)
            loader.launch_tag(root, scope)
    return plan
