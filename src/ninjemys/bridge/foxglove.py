"""The Foxglove WebSocket protocol (foxglove/ws-protocol ``docs/spec.md``, v1) for one client.

Channels are the graph's topics with encoding ``ros1``, schema name ``pkg/Type`` and the full
definition text (``ros1msg``) as schema (plus the ``json`` channels of an in-process app,
:mod:`ninjemys.bridge.appchannels`); message data is the TCPROS payload as received, never
deserialized (the tap subscribes raw). Client publishing sends the client's bytes as they are
(``publish_raw``), and service calls carry ROS 1 bytes both ways.
"""

from __future__ import annotations

import base64
import json
import logging
import struct
import threading
from collections.abc import Callable
from concurrent.futures import Executor, ThreadPoolExecutor
from typing import Any

from ninjemys.bridge.graph import Delivery
from ninjemys.bridge.outbox import Backlog, Outbox
from ninjemys.errors import NinjemysError

log = logging.getLogger(__name__)

SUBPROTOCOLS = ("foxglove.websocket.v1", "foxglove.sdk.v1")
_MESSAGE_HEAD = struct.Struct("<BIQ")  # opcode 0x01, subscription id, receive time (ns)
_TIME = struct.Struct("<BQ")  # opcode 0x02, time (ns)
_SERVICE_HEAD = struct.Struct("<BIII")  # opcode, service id, call id, encoding length
_CLIENT_MESSAGE_HEAD = struct.Struct("<BI")  # opcode 0x01, client channel id


class FoxgloveSession:
    """The Foxglove protocol for one connected client."""

    def __init__(self, gateway: Any, client_id: int, outbox: Outbox) -> None:
        self.gateway = gateway
        self.client_id = client_id
        self.outbox = outbox
        #: subscription id -> (channel id, topic): the topic kept, as a removed channel is no longer in
        #: the catalog when its subscriptions are dropped
        self._subs: dict[int, tuple[int, str]] = {}
        self._client_channels: dict[int, tuple[str, Any]] = {}  # client channel id -> (topic, publisher)
        self._param_names: set[str] = set()
        self.graph_subscribed = False
        self.backlog = Backlog()
        self._worker: Executor = ThreadPoolExecutor(1, thread_name_prefix=f"foxglove-{client_id}")
        self._lock = threading.Lock()
        self._closed = False

    # -- sending ------------------------------------------------------------------------------
    def send(self, obj: dict[str, Any]) -> None:
        self.outbox.put_control(json.dumps(obj))

    def status(self, level: int, message: str, op_id: str | None = None) -> None:
        out: dict[str, Any] = {"op": "status", "level": level, "message": message}
        if op_id is not None:
            out["id"] = op_id
        self.send(out)

    def hello(self) -> None:
        """serverInfo, then the current channels and services."""
        g = self.gateway
        caps = ["clientPublish", "parameters", "parametersSubscribe", "services", "connectionGraph"]
        if g.sim_time:
            caps.append("time")
        self.send(
            {
                "op": "serverInfo",
                "name": g.node.name,
                "capabilities": caps,
                "supportedEncodings": ["ros1"],
                "metadata": self._metadata(),
                "sessionId": g.session_id,
            }
        )
        self.send({"op": "advertise", "channels": list(g.catalog.channels.values())})
        services = list(g.catalog.services.values())
        if services:
            self.send({"op": "advertiseServices", "services": services})
        if g.master_error is not None:
            self.master_status(g.master_error)

    def master_status(self, error: str | None) -> None:
        """Tell the client the master is unreachable (a status with id ``master``), or no longer."""
        if error is None:
            self.send({"op": "removeStatus", "statusIds": ["master"]})
        else:
            self.status(2, error, "master")

    def _metadata(self) -> dict[str, str]:
        g = self.gateway
        meta = {"ROS_DISTRO": "noetic", "ROS_MASTER_URI": g.node.master_uri}
        if g.options.hide_own_node:
            meta["debugNodes"] = g.node.name
        return meta

    def send_time(self, ns: int) -> None:
        self.outbox.put("\0time", _TIME.pack(0x02, ns), 1)

    # -- receiving ----------------------------------------------------------------------------
    def receive(self, data: str | bytes) -> None:
        if self._closed:
            return
        if isinstance(data, bytes):
            self._binary(data)
            return
        try:
            msg = json.loads(data)
        except ValueError as exc:
            self.status(2, f"malformed JSON: {exc}")
            return
        if not isinstance(msg, dict) or not isinstance(msg.get("op"), str):
            self.status(2, "a message must be a JSON object with an 'op' string")
            return
        handler = getattr(self, "op_" + msg["op"], None)
        if handler is None:
            self.status(2, f"unknown op {msg['op']!r}")
            return
        self.backlog.add()
        self._worker.submit(self._run, handler, msg)

    def _run(self, handler: Callable[[dict[str, Any]], None], msg: dict[str, Any]) -> None:
        try:
            handler(msg)
        except (NinjemysError, KeyError, TypeError, ValueError) as exc:
            what = f"missing field {exc}" if isinstance(exc, KeyError) else f"{type(exc).__name__}: {exc}"
            self.status(2, f"{msg['op']}: {what}", msg.get("id") if isinstance(msg.get("id"), str) else None)
        except Exception as exc:
            log.exception("foxglove: op %s failed", msg["op"])
            self.status(2, f"{msg['op']}: {type(exc).__name__}: {exc}")
        finally:
            self.backlog.done()

    def _binary(self, data: bytes) -> None:
        if not data:
            self.status(2, "empty binary message")
            return
        opcode = data[0]
        if opcode == 0x01 and len(data) >= _CLIENT_MESSAGE_HEAD.size:
            _, channel = _CLIENT_MESSAGE_HEAD.unpack_from(data)
            entry = self._client_channels.get(channel)
            if entry is None:
                self.status(2, f"message data for unknown client channel {channel}")
                return
            try:
                entry[1].publish_raw(data[_CLIENT_MESSAGE_HEAD.size :])
            except NinjemysError as exc:
                self.status(2, f"publishing on {entry[0]}: {exc}")
        elif opcode == 0x02 and len(data) >= _SERVICE_HEAD.size:
            _, service_id, call_id, enc_len = _SERVICE_HEAD.unpack_from(data)
            encoding = data[_SERVICE_HEAD.size : _SERVICE_HEAD.size + enc_len].decode("utf-8", "replace")
            payload = data[_SERVICE_HEAD.size + enc_len :]
            self._dispatch_call(service_id, call_id, encoding, payload)
        else:
            self.status(2, f"unknown or truncated binary opcode 0x{opcode:02x}")

    # -- ops ----------------------------------------------------------------------------------
    def op_subscribe(self, msg: dict[str, Any]) -> None:
        for entry in msg["subscriptions"]:
            sub_id, channel_id = int(entry["id"]), int(entry["channelId"])
            channel = self.gateway.catalog.channel(channel_id)
            if channel is None:
                self.status(1, f"subscribe: unknown channel {channel_id}")
                continue
            topic = channel["topic"]
            with self._lock:
                if sub_id in self._subs:
                    self.status(1, f"subscribe: subscription id {sub_id} is already in use")
                    continue
                self._subs[sub_id] = (channel_id, topic)
            app = self.gateway.catalog.app.get(channel_id)
            if app is not None:  # a channel of this process's own app (a simulator's view)
                app.add((self, sub_id), self._sink(sub_id, topic))
                continue
            try:
                # published_as: a channel of a type learned from a publisher's definition is taken raw
                self.gateway.taps.add(
                    topic,
                    channel["schemaName"],
                    (self, sub_id),
                    self._sink(sub_id, topic),
                    published_as=channel["schemaName"],
                )
            except NinjemysError:
                with self._lock:
                    self._subs.pop(sub_id, None)
                raise

    def op_unsubscribe(self, msg: dict[str, Any]) -> None:
        self._unsubscribe([int(sub_id) for sub_id in msg["subscriptionIds"]])

    def channels_removed(self, channel_ids: list[int]) -> None:
        """The gateway unadvertised these channels: their subscriptions end with them, as in Foxglove's
        own server (a client subscribes again under the new channel when the topic comes back; the
        old subscription would otherwise go on taking the topic for an id nobody reads)."""
        gone = set(channel_ids)

        def drop() -> None:
            with self._lock:
                ended = [sub_id for sub_id, (channel_id, _) in self._subs.items() if channel_id in gone]
            self._unsubscribe(ended)

        if not self._closed:
            self._worker.submit(drop)

    def _unsubscribe(self, sub_ids: list[int]) -> None:
        for sub_id in sub_ids:
            with self._lock:
                entry = self._subs.pop(sub_id, None)
            if entry is not None:
                self._drop(sub_id, *entry)
                self.outbox.discard(f"{entry[1]}#{sub_id}")

    def _drop(self, sub_id: int, channel_id: int, topic: str) -> None:
        app = self.gateway.catalog.app.get(channel_id)
        if app is not None:
            app.remove((self, sub_id))
        else:
            self.gateway.taps.remove(topic, (self, sub_id))

    def _sink(self, sub_id: int, topic: str) -> Callable[[Delivery], None]:
        lane = f"{topic}#{sub_id}"
        put = self.outbox.put
        pack = _MESSAGE_HEAD.pack
        depth = self.gateway.options.queue_length

        key = ("foxglove", sub_id)

        def frame(d: Delivery) -> bytes:
            return pack(0x01, sub_id, d.stamp_ns) + bytes(d.data)

        def deliver(d: Delivery) -> None:
            # clients with the same subscription id (Foxglove numbers from 1) share one frame per message
            put(lane, d.encoded(key, frame), depth)

        return deliver

    def op_advertise(self, msg: dict[str, Any]) -> None:
        for channel in msg["channels"]:
            channel_id, topic = int(channel["id"]), str(channel["topic"])
            if channel.get("encoding") != "ros1":
                self.status(2, f"advertise {topic}: encoding must be ros1, got {channel.get('encoding')!r}")
                continue
            topic = self.gateway.node.resolve_name(topic)
            schema_name = str(channel["schemaName"])
            # a type we do not ship is learned from the definition the client sent
            msg_class = (
                self.gateway.publishers.learn(schema_name, str(channel["schema"]))
                if channel.get("schema")
                else None
            )
            pub = self.gateway.publishers.advertise(
                topic, schema_name, (self, channel_id), msg_class=msg_class
            )
            self._client_channels[channel_id] = (topic, pub)

    def op_unadvertise(self, msg: dict[str, Any]) -> None:
        for channel_id in msg["channelIds"]:
            entry = self._client_channels.pop(int(channel_id), None)
            if entry is not None:
                self.gateway.publishers.unadvertise(entry[0], (self, int(channel_id)))

    def op_getParameters(self, msg: dict[str, Any]) -> None:  # noqa: N802 (the protocol's op name)
        names = list(msg.get("parameterNames") or [])
        node = self.gateway.node
        if not names:
            names = node.get_param_names()
        params = []
        for name in names:
            if node.has_param(name):
                params.append(_param_value(name, node.get_param(name)))
        self._values(params, msg.get("id"))

    def op_setParameters(self, msg: dict[str, Any]) -> None:  # noqa: N802
        node = self.gateway.node
        names = []
        for entry in msg["parameters"]:
            name = str(entry["name"])
            names.append(name)
            if "value" not in entry or entry["value"] is None:
                if node.has_param(name):
                    node.delete_param(name)
                continue
            value = entry["value"]
            if entry.get("type") == "byte_array":
                value = base64.b64decode(value)
            elif entry.get("type") == "float64":
                value = float(value)
            elif entry.get("type") == "float64_array":
                value = [float(v) for v in value]
            node.set_param(name, value)
        if msg.get("id") is not None:
            params = [_param_value(n, node.get_param(n)) for n in names if node.has_param(n)]
            self._values(params, msg.get("id"))

    def _values(self, params: list[dict[str, Any]], op_id: Any) -> None:
        out: dict[str, Any] = {"op": "parameterValues", "parameters": params}
        if op_id is not None:
            out["id"] = op_id
        self.send(out)

    def op_subscribeParameterUpdates(self, msg: dict[str, Any]) -> None:  # noqa: N802
        names = list(msg.get("parameterNames") or []) or self.gateway.node.get_param_names()
        for name in names:
            if name not in self._param_names:
                self._param_names.add(name)
                self.gateway.watch_param(name)

    def op_unsubscribeParameterUpdates(self, msg: dict[str, Any]) -> None:  # noqa: N802
        names = list(msg.get("parameterNames") or []) or list(self._param_names)
        for name in names:
            self._param_names.discard(name)

    def param_changed(self, name: str, value: Any) -> None:
        if name in self._param_names or any(name.startswith(p.rstrip("/") + "/") for p in self._param_names):
            self._values([_param_value(name, value)], None)

    def op_subscribeConnectionGraph(self, msg: dict[str, Any]) -> None:  # noqa: N802
        self.graph_subscribed = True
        self.send(self.gateway.graph_update())
        self.gateway.sweep_bus()

    def op_unsubscribeConnectionGraph(self, msg: dict[str, Any]) -> None:  # noqa: N802
        self.graph_subscribed = False

    def _dispatch_call(self, service_id: int, call_id: int, encoding: str, payload: bytes) -> None:
        """Run a call on its service's lane; every way it can end answers the client at once (a
        response, or ``serviceCallFailure`` with the reason), and a hung one fails at the deadline."""
        service = self.gateway.catalog.services.get(service_id)
        if service is None:
            self._failure(service_id, call_id, f"unknown service id {service_id}")
            return
        if encoding != "ros1":
            self._failure(service_id, call_id, f"service call encoding must be ros1, got {encoding!r}")
            return
        name = service["name"]
        timeout = self.gateway.options.call_service_timeout

        def work(claim: Callable[[], bool]) -> None:
            try:
                response = self.gateway.services.call_raw(name, payload)
            except NinjemysError as exc:
                if claim():
                    self._failure(service_id, call_id, str(exc))
                return
            except Exception as exc:  # a gateway bug still answers this call, and is logged
                log.exception("foxglove: call to %s failed", name)
                if claim():
                    self._failure(service_id, call_id, f"{name}: {type(exc).__name__}: {exc}")
                return
            if claim():
                enc = b"ros1"
                head = _SERVICE_HEAD.pack(0x03, service_id, call_id, len(enc))
                self.outbox.put_control(head + enc + response)

        def expired() -> None:
            self._failure(service_id, call_id, f"service {name} did not answer within {timeout:g} s")

        try:
            self.gateway.services.dispatch(name, timeout, work, expired)
        except NinjemysError as exc:
            self._failure(service_id, call_id, str(exc))

    def _failure(self, service_id: int, call_id: int, message: str) -> None:
        self.send(
            {"op": "serviceCallFailure", "serviceId": service_id, "callId": call_id, "message": message}
        )

    # -- end ----------------------------------------------------------------------------------
    def close(self) -> None:
        self._closed = True

        def cleanup() -> None:
            for sub_id, (channel_id, topic) in list(self._subs.items()):
                self._drop(sub_id, channel_id, topic)
            self._subs.clear()
            for channel_id, (topic, _pub) in list(self._client_channels.items()):
                self.gateway.publishers.unadvertise(topic, (self, channel_id))
            self._client_channels.clear()

        self._worker.submit(cleanup)
        self._worker.shutdown(wait=False)


def _param_value(name: str, value: Any) -> dict[str, Any]:
    if isinstance(value, bytes | bytearray):
        return {"name": name, "value": base64.b64encode(bytes(value)).decode("ascii"), "type": "byte_array"}
    if isinstance(value, float):
        return {"name": name, "value": value, "type": "float64"}
    if isinstance(value, list) and value and all(isinstance(v, float) for v in value):
        return {"name": name, "value": value, "type": "float64_array"}
    return {"name": name, "value": value}
