"""Completion candidates for the bash functions in ``ninjemys/share/completion/ninjemys.bash``.

``python -m ninjemys.tools.complete KIND [ARG...] PREFIX`` prints, one per line, the candidates of
KIND that start with PREFIX:

=================  ====================================================================
topics             topic names in the graph (published or subscribed)
nodes              node names
services           service names
params             parameter names and the namespaces above them (``/turtlesim/``)
topic-type TOPIC   the type of TOPIC (``rostopic pub /chatter <Tab>``)
msgs / srvs        message / service types (``pkg/Type``)
msg-packages       packages holding messages (``srv-packages`` likewise)
packages           package names
pkg-dirs           ``pkg/sub/`` directories (roscd); ``pkg-paths`` adds files (rosls)
pkg-files PKG      file names inside a package (rosed)
executables PKG    what ``rosrun PKG`` can run
launch-files PKG   launch files of a package
launch-args FILE   ``name:=`` for a launch file's arguments (``launch-args PKG FILE`` inside a package)
msg-proto TYPE     the YAML prototype of a message (``rostopic pub ... TYPE <Tab>``)
srv-proto SERVICE  the YAML prototype of the request of a live service (``rosservice call``)
=================  ====================================================================

Every Tab press starts this module, so it answers with one master call at most and imports almost
nothing: the XML-RPC exchange is a raw socket and a tiny tokenizer, package scans use ``os``
(:mod:`ninjemys.tools.complete_pkgs`). A missing master or package prints nothing and exits 0:
completion must never print an error into the user's command line or hang the shell.

``python -m ninjemys.tools.complete --path`` prints the location of the bash file, and
``ninjemys-completion`` prints the bash code itself (``eval "$(ninjemys-completion)"`` in ~/.bashrc).
"""

from __future__ import annotations

import os
import sys

from ninjemys.share.completion import BASH_FILE

TYPE_CHECKING = False  # typing itself is not worth importing on every Tab press
if TYPE_CHECKING:
    from collections.abc import Callable
    from types import ModuleType

    from ninjemys.master.snapshot import GraphSnapshot

#: a completion that waits longer than this for the master is worse than none
MASTER_TIMEOUT = 1.0
CALLER_ID = "/ninjemys_complete"


# -- one XML-RPC call to the master, with nothing heavier than a socket --------------------------


def _xml_escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _request(method: str, params: tuple[str, ...], host: str) -> bytes:
    body = "".join(f"<param><value><string>{_xml_escape(p)}</string></value></param>" for p in params)
    payload = (
        f"<?xml version='1.0'?><methodCall><methodName>{method}</methodName>"
        f"<params>{body}</params></methodCall>"
    ).encode()
    signature = ""
    if any(
        os.environ.get(v)
        for v in ("NINJEMYS_SECRET", "NINJEMYS_SECRET_FILE", "NINJEMYS_KEYS_FILE", "NINJEMYS_KEY")
    ):
        from ninjemys.net import auth  # only a graph with a secret pays for signing

        signature = auth.http_header_line(payload, params[0] if params else "")
    head = (
        f"POST /RPC2 HTTP/1.1\r\nHost: {host}\r\nContent-Type: text/xml\r\n"
        f"Content-Length: {len(payload)}\r\n{signature}Connection: close\r\n\r\n"
    ).encode()
    return head + payload


def _read_response(sock: object) -> bytes:
    """The body of one HTTP response (Content-Length, else read to the close)."""
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = sock.recv(65536)  # type: ignore[attr-defined]
        if not chunk:
            return b""
        data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    length = None
    for line in head.split(b"\r\n")[1:]:
        key, _, value = line.partition(b":")
        if key.strip().lower() == b"content-length":
            length = int(value.strip())
    while length is None or len(body) < length:
        chunk = sock.recv(65536)  # type: ignore[attr-defined]
        if not chunk:
            break
        body += chunk
    return body if length is None else body[:length]


class _ValueDecoder:
    """Builds the Python value of an XML-RPC response from start/text/end events."""

    _SCALARS = frozenset({"string", "int", "i4", "i8", "boolean", "double", "base64", "nil"})

    def __init__(self) -> None:
        self.stack: list[list | dict] = [[]]
        self.member_names: list[str] = []
        self.text: list[str] = []
        self.typed = True

    def start(self, tag: str, _attrs: object) -> None:
        self.text = []
        if tag == "value":
            self.typed = False
        elif tag == "array":
            self.stack.append([])
            self.typed = True
        elif tag == "struct":
            self.stack.append({})
            self.typed = True
        elif tag in self._SCALARS:
            self.typed = True

    def chars(self, data: str) -> None:
        self.text.append(data)

    def end(self, tag: str) -> None:
        text = "".join(self.text)
        match tag:
            case "string" | "base64":
                self._add(text)
            case "int" | "i4" | "i8":
                self._add(int(text.strip()))
            case "boolean":
                self._add(text.strip() == "1")
            case "double":
                self._add(float(text.strip()))
            case "nil":
                self._add(None)
            case "array" | "struct":
                self._add(self.stack.pop())
            case "name":
                self.member_names.append(text)
            case "value" if not self.typed:
                self._add(text)

    def _add(self, value: object) -> None:
        top = self.stack[-1]
        if isinstance(top, dict):
            top[self.member_names.pop() if self.member_names else ""] = value
        else:
            top.append(value)
        self.typed = True
        self.text = []


def _unescape(text: str) -> str:
    if "&" not in text:
        return text
    if "&#" in text:
        pieces = text.split("&#")
        out = [pieces[0]]
        for piece in pieces[1:]:
            number, sep, rest = piece.partition(";")
            try:
                code = int(number[1:], 16) if number[:1] in "xX" and number else int(number)
                out.append(chr(code) + rest if sep else "&#" + piece)
            except ValueError:
                out.append("&#" + piece)
        text = "".join(out)
    for entity, char in (("&lt;", "<"), ("&gt;", ">"), ("&quot;", '"'), ("&apos;", "'"), ("&amp;", "&")):
        text = text.replace(entity, char)
    return text


def decode_response(body: str) -> object | None:
    """The first value of an XML-RPC response body, or None for a fault or garbage.

    A ten-line tokenizer instead of expat or xmlrpc.client: XML-RPC is a handful of tags without
    attributes, and each import would cost a Tab press more than the master call does.
    """
    decoder = _ValueDecoder()
    in_fault = False
    for piece in body.split("<")[1:]:
        tag, sep, text = piece.partition(">")
        if not sep or tag[:1] in "?!":
            continue
        if tag.startswith("/"):
            decoder.end(tag[1:].strip())
        elif tag.endswith("/"):  # <string/>, <value/>: an empty element
            name = tag[:-1].strip()
            decoder.start(name, None)
            decoder.end(name)
        else:
            name = tag.strip()
            in_fault = in_fault or name == "fault"
            decoder.start(name, None)
        if text:
            decoder.chars(_unescape(text))
    values = decoder.stack[0]
    return None if in_fault or not values else values[0]


def master_call(method: str, *params: str) -> object | None:
    """The value of ``[code, status, value]`` from the master at ROS_MASTER_URI, or None on any failure.

    ``_socket`` rather than ``socket``: the wrapper module's enum/selectors imports double the cost
    of a completion. The host goes to getaddrinfo as bytes so the idna codec is never loaded.
    """
    import _socket

    uri = os.environ.get("ROS_MASTER_URI", "http://localhost:11311/")
    hostport = uri.partition("://")[2].partition("/")[0]
    host, _, port = hostport.rpartition(":")
    try:
        addresses = _socket.getaddrinfo(host.strip("[]").encode(), int(port), 0, _socket.SOCK_STREAM)
    except (OSError, ValueError, UnicodeError):
        return None
    body = b""
    for family, kind, proto, _name, address in addresses:
        sock = _socket.socket(family, kind, proto)
        try:
            sock.settimeout(MASTER_TIMEOUT)
            sock.connect(address)
            sock.sendall(_request(method, (CALLER_ID, *params), hostport))
            body = _read_response(sock)
            break
        except OSError:
            continue
        finally:
            sock.close()
    result = decode_response(body.decode("utf-8", "replace")) if body else None
    if isinstance(result, list) and len(result) == 3 and result[0] == 1:
        return result[2]
    return None


# -- the kinds ------------------------------------------------------------------------------------


def _snapshot() -> GraphSnapshot:
    from ninjemys.master.snapshot import GraphSnapshot

    state = master_call("getSystemState")
    return GraphSnapshot.from_system_state(
        state if isinstance(state, list) and len(state) == 3 else [[], [], []]
    )


def topics() -> list[str]:
    return _snapshot().topic_names()


def nodes() -> list[str]:
    return _snapshot().node_names()


def services() -> list[str]:
    return sorted(_snapshot().services)


def params() -> list[str]:
    names = master_call("getParamNames")
    found: set[str] = set()
    for name in names if isinstance(names, list) else []:
        found.add(name)
        parts = name.split("/")[1:-1]
        for depth in range(1, len(parts) + 1):
            found.add("/" + "/".join(parts[:depth]) + "/")
    return sorted(found)


def topic_type(topic: str) -> list[str]:
    types = master_call("getTopicTypes")
    wanted = topic if topic.startswith("/") else "/" + topic
    return [t for name, t in (types if isinstance(types, list) else []) if name == wanted]


def service_request_prototype(service: str) -> list[str]:
    from ninjemys.errors import NinjemysError
    from ninjemys.tools.complete_proto import request_prototype
    from ninjemys.tools.rosservice import probe

    name = service if service.startswith("/") else "/" + service
    uri = master_call("lookupService", name)
    if not isinstance(uri, str):
        return []
    try:
        service_type = probe(name, uri, timeout=MASTER_TIMEOUT).get("type")
        return [request_prototype(service_type)] if service_type else []
    except NinjemysError:
        return []


def message_prototype(type_name: str) -> list[str]:
    from ninjemys.errors import NinjemysError
    from ninjemys.tools.complete_proto import message_prototype as proto

    try:
        return [proto(type_name)]
    except NinjemysError:
        return []


def _interface_packages(kind: str) -> list[str]:
    from ninjemys.tools.complete_pkgs import interface_types

    return sorted({t.partition("/")[0] for t in interface_types(kind)})


def _launch_args(*where: str) -> list[str]:
    from ninjemys.tools.complete_pkgs import find_package_file, launch_args

    path = find_package_file(where[0], where[1]) if len(where) == 2 else where[0]
    return launch_args(path) if path else []


def _pkgs() -> ModuleType:
    from ninjemys.tools import complete_pkgs

    return complete_pkgs


#: kind -> (number of arguments before the prefix, producer); producers return unfiltered candidates
#: except the path kinds, which filter by the prefix themselves (they list one directory level)
KINDS: dict[str, tuple[int, Callable[..., list[str]]]] = {
    "topics": (0, topics),
    "nodes": (0, nodes),
    "services": (0, services),
    "params": (0, params),
    "topic-type": (1, topic_type),
    "msgs": (0, lambda: _pkgs().interface_types("msg")),
    "srvs": (0, lambda: _pkgs().interface_types("srv")),
    "msg-packages": (0, lambda: _interface_packages("msg")),
    "srv-packages": (0, lambda: _interface_packages("srv")),
    "packages": (0, lambda: sorted(_pkgs().packages())),
    "pkg-files": (
        1,
        lambda pkg: [os.path.basename(r) for r, _ in _pkgs().package_files(_pkgs().packages()[pkg])],
    ),
    "executables": (1, lambda pkg: _pkgs().executables(pkg)),
    "launch-files": (1, lambda pkg: _pkgs().launch_files(pkg)),
    "launch-args": (1, _launch_args),
    "msg-proto": (1, message_prototype),
    "srv-proto": (1, service_request_prototype),
}
#: kinds whose producer takes the prefix itself
PATH_KINDS: dict[str, Callable[[str], list[str]]] = {
    "pkg-dirs": lambda spec: _pkgs().package_subpaths(spec, files=False),
    "pkg-paths": lambda spec: _pkgs().package_subpaths(spec, files=True),
}


def candidates(kind: str, args: list[str]) -> list[str]:
    """The candidates of ``kind`` for ``args`` (its arguments, then the prefix being completed)."""
    if kind in PATH_KINDS:
        return PATH_KINDS[kind](args[0] if args else "")
    if kind == "launch-args" and len(args) == 3:  # PKG FILE PREFIX
        arguments, prefix = args[:2], args[2]
        producer = _launch_args
    elif kind in KINDS:
        count, producer = KINDS[kind]
        if len(args) < count:
            return []
        arguments, prefix = args[:count], (args[count] if len(args) > count else "")
    else:
        raise KeyError(kind)
    try:
        found = producer(*arguments)
    except (KeyError, OSError):
        return []
    seen: dict[str, None] = {}
    for candidate in found:
        if candidate.startswith(prefix):
            seen.setdefault(candidate, None)
    return list(seen)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] == "--path":
        print(BASH_FILE)
        return 0
    if args and args[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    if not args:
        print(
            "ERROR: missing completion kind (python -m ninjemys.tools.complete --help lists them)",
            file=sys.stderr,
        )
        return 2
    try:
        found = candidates(args[0], args[1:])
    except KeyError:
        print(f"ERROR: unknown completion kind [{args[0]}]", file=sys.stderr)
        return 2
    if found:
        sys.stdout.write("\n".join(found) + "\n")
    return 0


def script(python: str = sys.executable) -> str:
    """The bash code to ``eval``: the completion file, bound to this interpreter."""
    with open(BASH_FILE, encoding="utf-8") as f:
        text = f.read()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    return f"_NJ_PY={_shell_quote(python)}\n_NJ_ROOT={_shell_quote(root)}\n{text}"


def _shell_quote(text: str) -> str:
    return "'" + text.replace("'", "'\\''") + "'"


def completion_main() -> None:
    """``ninjemys-completion [--path]``: print the bash completion code (or where its file is)."""
    args = sys.argv[1:]
    if args and args[0] in ("-h", "--help"):
        print('usage: ninjemys-completion [--path]\n\nAdd  eval "$(ninjemys-completion)"  to ~/.bashrc')
        sys.exit(0)
    if args and args[0] == "--path":
        print(BASH_FILE)
        sys.exit(0)
    if args:
        print(f"ERROR: unknown argument [{args[0]}] (usage: ninjemys-completion [--path])", file=sys.stderr)
        sys.exit(2)
    sys.stdout.write(script())
    sys.exit(0)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (BrokenPipeError, KeyboardInterrupt):
        sys.exit(1)
