"""Zenoh-side access for the bridge, tied to the graph's authentication (ninjemys.net.auth).

With authentication on, a bridge joins the Zenoh network with Zenoh's own user/password
authentication (``transport/auth/usrpwd``): every link a bridge opens presents a user and password,
and every link it accepts must present a pair from its dictionary. Both come from the graph's
credentials, so one secret opens the ROS graph, its gateway and its Zenoh links, and a bridge (or any
Zenoh peer) without it cannot join, hence cannot read or write a key. Zenoh also refuses a link from
a secured bridge to a peer that does not authenticate, so a secured graph never talks to an open one.

- shared secret: user ``ninjemys``, password HMAC-SHA256(secret, "zenoh-bridge-ros1 usrpwd v1");
- per-node keys: user the bridge's node name, password the same HMAC of that node's key; a listening
  bridge admits every *name* its keys file lists (patterns cannot be enumerated: list bridges by name).

The password is derived, not the secret itself: Zenoh's dictionary is a file, and a leaked file gives
a Zenoh login, never the graph's secret. The file is written 0600 in a private directory and removed
as soon as the session is open (Zenoh reads it when it starts).

Zenoh's TLS (``tls/`` endpoints with certificates in ``--config``) encrypts the links on top of this;
it needs certificates the secret cannot give, so it stays the user's configuration.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

from ninjemys.errors import NinjemysError
from ninjemys.net.auth import Credentials

SHARED_USER = "ninjemys"
_CONTEXT = b"zenoh-bridge-ros1 usrpwd v1"


class AccessError(NinjemysError):
    """The bridge has no key to join the Zenoh network with (per-node keys without one for its name)."""


def password(key: bytes) -> str:
    """The Zenoh password derived from a graph key (hex of an HMAC: one-way, no ':' or newline)."""
    import hashlib
    import hmac

    return hmac.new(key, _CONTEXT, hashlib.sha256).hexdigest()


def logins(creds: Credentials, bridge_name: str) -> tuple[str, str, list[tuple[str, str]]]:
    """(user, password) this bridge presents, and the (user, password) pairs it admits."""
    if creds.single is not None:
        pair = (SHARED_USER, password(creds.single.key))
        return pair[0], pair[1], [pair]
    own = creds.secret_for(bridge_name)
    if own is None:
        raise AccessError(
            f"{creds.source}: no key for the bridge's node {bridge_name} (set NINJEMYS_KEY or list it)"
        )
    admitted = [(name, password(key)) for name, key in creds.listed_names()]
    return bridge_name, password(own), admitted


@contextmanager
def usrpwd_settings(creds: Credentials | None, bridge_name: str) -> Iterator[dict[str, object]]:
    """The Zenoh settings (key -> JSON value) for the session while it opens ({} when authentication
    is off). The dictionary file exists only inside the ``with``."""
    if creds is None:
        yield {}
        return
    import tempfile

    user, secret, admitted = logins(creds, bridge_name)
    with tempfile.TemporaryDirectory(prefix="ninjemys-zenoh-") as folder:  # 0700
        path = os.path.join(folder, "usrpwd")
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.writelines(f"{name}:{pw}\n" for name, pw in admitted)
        yield {"transport/auth/usrpwd": {"user": user, "password": secret, "dictionary_file": path}}
