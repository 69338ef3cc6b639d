"""Graph page: time to show a 100-node graph in headless chromium, and to reflect a node coming and going.

    .venv/bin/python bench/web_graph.py [--nodes 100]

The page gets its data through the gateway on the web tools' server (the connection graph and the
getBusInfo sweep of its rosBus extension), as the rqt_graph command runs it. A helper process runs N ninjemys nodes (node i publishes /g<i%10>/t<i> and subscribes to the previous
node's topic, so the graph is a chain through 10 namespaces). The browser is Debian's chromium via
Playwright. ROS 1's rqt_graph is a Qt desktop tool (not installed here), so there is nothing to run
side by side; its refresh is manual or a 1 s auto-refresh of the same master calls.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.bridge.server import Gateway, GatewayOptions  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import run_master  # noqa: E402
from ninjemys.web.app import WebApp  # noqa: E402

NODES_SCRIPT = textwrap.dedent(
    """
    import sys
    from std_msgs.msg import String
    from ninjemys.node import Node
    n = int(sys.argv[1])
    nodes = []
    for i in range(n):
        node = Node(f"n{i}", namespace=f"/g{i % 10}")
        node.publisher(f"/g{i % 10}/t{i}", String)
        if i:
            node.subscriber(f"/g{(i - 1) % 10}/t{i - 1}", String, lambda m: None)
        nodes.append(node)
    print("ready", flush=True)
    extra = None
    for line in sys.stdin:
        if line.strip() == "add":
            extra = Node("newcomer")
            extra.publisher("/g0/t0", String)
            print("added", flush=True)
        elif line.strip() == "remove":
            extra.shutdown("bench")
            print("removed", flush=True)
    for node in nodes:
        node.shutdown("bench over")
    """
)

# navigation start -> the first moment the page holds N node shapes, in the page's performance clock
DRAWN_AT = """
window.__drawnAt = null;
new MutationObserver(() => {
  if (window.__drawnAt === null && document.querySelectorAll('g.node').length >= %d) window.__drawnAt = performance.now();
}).observe(document, { subtree: true, childList: true });
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--nodes", type=int, default=100)
    options = parser.parse_args()
    from playwright.sync_api import sync_playwright

    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        t0 = time.monotonic()
        helper = subprocess.Popen(
            [sys.executable, "-c", NODES_SCRIPT, str(options.nodes)],
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert helper.stdout is not None and helper.stdin is not None
        helper.stdout.readline()
        print(f"{options.nodes} nodes registered in {time.monotonic() - t0:.1f} s (helper process)")
        t0 = time.monotonic()
        # as the rqt_graph command runs it: the page's data comes through a gateway on its server
        node = Node("bench_rqt_graph", master_uri=uri)
        gateway = Gateway(
            GatewayOptions(node_name=node.name, hide_own_node=True, update_period=0.5), node=node
        )
        gateway.start()
        app = WebApp(uri, caller_id=node.name)
        app.add_gateway(gateway)
        url = app.start()
        while len(gateway.catalog.node_names()) < options.nodes:
            time.sleep(0.01)
        first_graph = time.monotonic() - t0
        try:
            with sync_playwright() as pw:
                browser = pw.chromium.launch(
                    executable_path="/usr/bin/chromium", args=["--no-sandbox", "--disable-gpu"]
                )
                page = browser.new_page(viewport={"width": 1400, "height": 900})
                want = options.nodes
                # the page's own clock too: Playwright's polling round trips add 100-300 ms under load
                page.add_init_script(DRAWN_AT % want)
                t0 = time.monotonic()
                page.goto(url)
                page.wait_for_function(
                    f"document.querySelectorAll('g.node').length >= {want}", polling="raf", timeout=60000
                )
                shown = time.monotonic() - t0
                shown_page = page.evaluate("window.__drawnAt")
                t0 = time.monotonic()
                page.reload()
                page.wait_for_function(
                    f"document.querySelectorAll('g.node').length >= {want}", polling="raf", timeout=60000
                )
                reshown = time.monotonic() - t0
                reshown_page = page.evaluate("window.__drawnAt")
                render_ms = page.evaluate(
                    "() => { const t = performance.now(); render(); return performance.now() - t; }"
                )
                t0 = time.monotonic()
                helper.stdin.write("add\n")
                helper.stdin.flush()
                helper.stdout.readline()
                t_reg = time.monotonic() - t0
                # polled every frame: wait_for_selector backs off to 500 ms between checks
                page.wait_for_function(
                    "document.querySelector('g.node[data-name=\"/newcomer\"]') !== null",
                    polling="raf",
                    timeout=30000,
                )
                appear = time.monotonic() - t0
                t0 = time.monotonic()
                helper.stdin.write("remove\n")
                helper.stdin.flush()
                helper.stdout.readline()
                page.wait_for_function(
                    "document.querySelector('g.node[data-name=\"/newcomer\"]') === null",
                    polling="raf",
                    timeout=30000,
                )
                vanish = time.monotonic() - t0
                browser.close()
        finally:
            app.stop()
            gateway.shutdown()
            node.shutdown("bench over")
            helper.stdin.close()
            try:
                helper.wait(20)
            except subprocess.TimeoutExpired:
                helper.kill()
                helper.wait()
    print("graph page (machine shared, figures noisy; master polled every 0.5 s):")
    print(
        f"  web tools start -> first {options.nodes}-node graph  {first_graph * 1000:7.0f} ms (gateway's master poll)"
    )
    print(
        f"  open page -> {options.nodes}-node graph drawn     {shown * 1000:7.0f} ms (fresh browser;"
        f" page's clock {shown_page:.0f} ms)"
    )
    print(
        f"  reload    -> {options.nodes}-node graph drawn     {reshown * 1000:7.0f} ms (page's clock {reshown_page:.0f} ms)"
    )
    print(f"  one full re-layout + SVG render           {render_ms:7.0f} ms")
    print(
        f"  node registered -> shown                  {appear * 1000:7.0f} ms (registration {t_reg * 1000:.0f} ms)"
    )
    print(f"  node shut down -> gone from the page      {vanish * 1000:7.0f} ms")
    print("ROS 1 reference: rqt_graph (Qt) is not installed here; it refreshes on demand or every 1 s.")


if __name__ == "__main__":
    main()
