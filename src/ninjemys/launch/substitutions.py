"""Substitution args: ``$(arg)``, ``$(env)``, ``$(optenv)``, ``$(find)``, ``$(anon)``, ``$(dirname)``, ``$(eval)``.

Semantics follow roslaunch: ``$(eval expr)`` must be the whole value; otherwise env/optenv/dirname/
anon/arg are replaced first and ``$(find pkg)`` last (so ``$(find $(arg p))`` works). ``$(anon x)``
is stable within one launch. ``$(eval)`` sees the args as variables (auto-typed), the functions
``arg``/``anon``/``dirname``/``env``/``optenv``/``find``, ``math``, ``true``/``false``, and rejects
``__`` so it cannot reach Python internals.
"""

from __future__ import annotations

import builtins
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ninjemys.errors import LaunchError
from ninjemys.names import anonymous_name

COMMANDS = ("find", "env", "optenv", "dirname", "anon", "arg")

#: builtins $(eval) offers: ROS 1 leaks all of Python's builtins into eval; these are the ones
#: launch files use, without open/exec/eval/__import__ (and ``__`` is rejected anyway).
_SAFE_BUILTINS = (
    "abs all any bin bool chr dict divmod enumerate filter float format hex int isinstance len list map max "
    "min oct ord pow range repr reversed round set sorted str sum tuple zip"
).split()


class ArgNotSet(LaunchError):
    """``$(arg name)`` of an arg that has no value; ``name`` is the arg."""

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(f"arg '{name}' is not set")


@dataclass
class SubstitutionContext:
    """What substitutions can see: args in scope, the current file, anon names, env, package lookup."""

    args: dict[str, str] = field(default_factory=dict)
    filename: str | None = None
    anons: dict[str, str] = field(default_factory=dict)
    env: Mapping[str, str] = field(default_factory=lambda: os.environ)
    find: Callable[[str], str] | None = None


def collect(text: str) -> list[str]:
    """The bodies of every ``$(...)`` in ``text`` (no nesting: the first ``)`` closes)."""
    bodies: list[str] = []
    i = 0
    while True:
        start = text.find("$(", i)
        if start < 0:
            return bodies
        end = text.find(")", start + 2)
        if end < 0:
            raise LaunchError(f"unterminated substitution in [{text}]: missing ')'")
        body = text[start + 2 : end]
        if "$" in body:
            # nested substitution: resolve the inner one first, the outer in the next pass
            inner = body.rfind("$(")
            if inner < 0:
                raise LaunchError(f"Dollar signs '$' cannot be inside of substitution args [{text}]")
            i = start + 2 + inner
            continue
        bodies.append(body)
        i = end + 1


def _auto(value: str) -> Any:
    from ninjemys.launch.values import convert_value

    return convert_value(value, "auto")


def _eval(expr: str, ctx: SubstitutionContext) -> str:
    if "__" in expr:
        raise LaunchError("$(eval ...) may not contain double underscore expressions")

    def arg(name: str) -> Any:
        if name not in ctx.args:
            raise ArgNotSet(name)
        return _auto(ctx.args[name])

    def env(name: str) -> str:
        if name not in ctx.env:
            raise LaunchError(f"environment variable '{name}' is not set")
        return ctx.env[name]

    def optenv(name: str, default: str = "") -> str:
        return ctx.env.get(name, default)

    def anon(name: str) -> str:
        return ctx.anons.setdefault(name, anonymous_name(name))

    def dirname() -> str:
        return _dirname(ctx)

    def find(pkg: str) -> str:
        return _find(ctx, pkg)

    functions: dict[str, Any] = {k: v for k, v in vars(math).items() if not k.startswith("_")}
    functions.update(
        true=True,
        false=False,
        arg=arg,
        env=env,
        optenv=optenv,
        anon=anon,
        dirname=dirname,
        find=find,
    )
    functions["True"] = True
    functions["False"] = False
    safe_builtins = {name: getattr(builtins, name) for name in _SAFE_BUILTINS}

    class Names(dict):
        def __missing__(self, key: str) -> Any:
            if key in ctx.args:
                return _auto(ctx.args[key])
            raise KeyError(key)

    try:
        return str(eval(expr, {"__builtins__": safe_builtins}, Names(functions)))  # noqa: S307 - sandboxed, see docstring
    except LaunchError:
        raise
    except Exception as exc:
        raise LaunchError(f"$(eval {expr}) failed: {type(exc).__name__}: {exc}") from None


def _dirname(ctx: SubstitutionContext) -> str:
    if not ctx.filename:
        raise LaunchError("Cannot substitute $(dirname), no file/directory information available.")
    return os.path.abspath(os.path.dirname(ctx.filename))


def _find(ctx: SubstitutionContext, pkg: str) -> str:
    if ctx.find is None:
        from ninjemys.packages.discovery import PackageIndex

        index = PackageIndex.from_environment(ctx.env)
        ctx.find = lambda name: str(index.find(name).path)
    try:
        return ctx.find(pkg)
    except LaunchError:
        raise
    except Exception as exc:
        raise LaunchError(f"$(find {pkg}): {exc}") from None


def _replace_once(text: str, body: str, value: str) -> str:
    return text.replace(f"$({body})", value)


def _apply(text: str, ctx: SubstitutionContext, allowed: tuple[str, ...]) -> str:
    for body in collect(text):
        words = body.split()
        if not words or words[0] not in COMMANDS:
            raise LaunchError(f"Unknown substitution command [{body}]. Valid commands are {list(COMMANDS)}")
        command, params = words[0], words[1:]
        if command not in allowed:
            continue
        if command == "arg":
            if len(params) != 1:
                raise LaunchError(f"$(arg var) must specify exactly one arg name [{body}]")
            if params[0] not in ctx.args:
                raise ArgNotSet(params[0])
            value = ctx.args[params[0]]
        elif command == "env":
            if len(params) != 1:
                raise LaunchError(f"$(env var) command only accepts one argument [{body}]")
            if params[0] not in ctx.env:
                raise LaunchError(f"environment variable '{params[0]}' is not set")
            value = ctx.env[params[0]]
        elif command == "optenv":
            if not params:
                raise LaunchError(f"$(optenv var) must specify an environment variable [{body}]")
            value = ctx.env.get(params[0], " ".join(params[1:]))
        elif command == "anon":
            if len(params) != 1:
                raise LaunchError(f"$(anon var) must specify exactly one name [{body}]")
            value = ctx.anons.setdefault(params[0], anonymous_name(params[0]))
        elif command == "dirname":
            value = _dirname(ctx)
        else:  # find
            if len(params) != 1:
                raise LaunchError(f"$(find pkg) command only accepts one argument [{body}]")
            text = _replace_find(text, body, _find(ctx, params[0]))
            continue
        text = _replace_once(text, body, value)
    return text


def _replace_find(text: str, body: str, pkg_path: str) -> str:
    """Each ``$(find pkg)`` with the path written right after it (up to the next space) joined on as
    roslaunch does, ``os.path.join(pkg_path, path)``: ``$(find styx)../../data/x.csv`` (no slash, as
    course launch files write it) is ``<styx>/../../data/x.csv``, not a sibling ``styx..`` directory."""
    command = f"$({body})"
    done = ""
    while command in text:
        start = text.index(command)
        after = text[start + len(command) :]
        space = after.find(" ")
        path, rest = (after, "") if space < 0 else (after[:space], after[space:])
        if path.startswith(("/", "\\")):
            path = path[1:]
        path = path.replace("\\", os.sep)
        joined = os.path.join(pkg_path, path) if path else pkg_path
        done += text[:start] + joined
        text = rest
    return done + text


def resolve(text: str | None, ctx: SubstitutionContext) -> str | None:
    """``text`` with every substitution replaced; None and ``$``-free text pass through unchanged."""
    if not text or "$" not in text:
        return text
    if text.startswith("$(eval ") and text.endswith(")"):
        return _eval(text[7:-1], ctx)
    previous = None
    while previous != text and "$(" in text:
        previous = text
        text = _apply(text, ctx, ("env", "optenv", "dirname", "anon", "arg"))
        text = _apply(text, ctx, ("find",))
    return text
