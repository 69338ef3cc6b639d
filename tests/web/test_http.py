"""The stdlib HTTP server: routes, static files, errors, bad input."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

from ninjemys.serve.http import HttpError, HttpServer, Request, Response


async def _request(port: int, raw: bytes) -> bytes:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    writer.write(raw)
    await writer.drain()
    data = await asyncio.wait_for(reader.read(), 5)
    writer.close()
    return data


def test_routes_static_errors(tmp_path: Path) -> None:
    (tmp_path / "a.js").write_text("let x = 1;")

    def boom(_r: Request) -> Response:
        raise RuntimeError("handler bug")

    def missing(_r: Request) -> Response:
        raise HttpError(404, "no turtle")

    async def scenario() -> None:
        server = HttpServer("127.0.0.1", 0)
        server.route("GET", "/json", lambda r: Response({"name": r.arg("name")}))
        server.route("GET", "/boom", boom)
        server.route("GET", "/missing", missing)
        server.static("/static", tmp_path)
        await server.start()
        try:
            ok = await _request(
                server.port, b"GET /json?name=%2Fchatter HTTP/1.1\r\nConnection: close\r\n\r\n"
            )
            assert ok.startswith(b"HTTP/1.1 200 OK")
            assert json.loads(ok.split(b"\r\n\r\n", 1)[1]) == {"name": "/chatter"}
            js = await _request(server.port, b"GET /static/a.js HTTP/1.1\r\nConnection: close\r\n\r\n")
            assert b"javascript" in js and js.endswith(b"let x = 1;")
            escape = await _request(
                server.port, b"GET /static/../../etc/passwd HTTP/1.1\r\nConnection: close\r\n\r\n"
            )
            assert escape.startswith(b"HTTP/1.1 404")
            bug = await _request(server.port, b"GET /boom HTTP/1.1\r\nConnection: close\r\n\r\n")
            assert bug.startswith(b"HTTP/1.1 500") and b"handler bug" in bug
            assert (
                await _request(server.port, b"GET /missing HTTP/1.1\r\nConnection: close\r\n\r\n")
            ).startswith(b"HTTP/1.1 404")
            garbage = await _request(server.port, b"HELLO\r\n\r\n")
            assert garbage.startswith(b"HTTP/1.1 400")
            huge = await _request(server.port, b"POST /json HTTP/1.1\r\nContent-Length: 999999999\r\n\r\n")
            assert huge.startswith(b"HTTP/1.1 413")
            # still serving after all that
            again = await _request(server.port, b"GET /json HTTP/1.1\r\nConnection: close\r\n\r\n")
            assert again.startswith(b"HTTP/1.1 200")
        finally:
            await server.close()

    asyncio.run(scenario())
