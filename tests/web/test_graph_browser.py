"""The graph page in a real headless chromium: talker -> /chatter -> listener, live updates, and the
topic details (rate and last message) watched through the gateway."""

from __future__ import annotations

import signal

import pytest
from web_helpers import LISTENER, ROBOT_BASE, TALKER, graph_app

pytestmark = [pytest.mark.ros1, pytest.mark.browser]


def test_graph_page_shows_chatter_and_updates_on_kill(ros1_master: str, rospy_node, browser_page) -> None:  # type: ignore[no-untyped-def]
    with graph_app(ros1_master) as app:
        rospy_node(TALKER)
        listener = rospy_node(LISTENER)
        rospy_node(ROBOT_BASE)
        page = browser_page
        page.goto(app.url)
        page.wait_for_selector('g.node[data-name="/talker"]', timeout=20000)
        page.wait_for_selector('g.node[data-name="/listener"]', timeout=20000)
        page.wait_for_selector('g.topic[data-name="/chatter"]', timeout=20000)
        assert page.locator('path.edge[data-source="/talker"][data-target="/chatter"]').count() == 1
        assert page.locator('path.edge[data-source="/chatter"][data-target="/listener"]').count() == 1
        # /rosout is hidden by default ("Hide debug"); the master has no rosout node here anyway
        assert page.locator('g.topic[data-name="/rosout"]').count() == 0

        # namespace grouping: /robot/base sits in a /robot group box (and not when grouping is off)
        page.wait_for_selector('g.node[data-name="/robot/base"]', timeout=20000)
        assert page.locator('g.group[data-name="/robot"]').count() == 1
        page.uncheck("#group")
        assert page.locator("g.group").count() == 0
        page.check("#group")

        # clicking the topic shows its type, then its rate and last message (subscribed through the
        # gateway, whose node stays hidden as debug plumbing)
        page.click('g.topic[data-name="/chatter"]')
        page.wait_for_selector('#details dd[data-key="type"]:has-text("std_msgs/String")', timeout=10000)
        page.wait_for_selector('#details dd[data-key="rate"]:has-text("Hz")', timeout=20000)
        page.wait_for_function(
            "document.getElementById('details-message').textContent.includes('hello world')", timeout=10000
        )
        assert page.locator('g.node[data-name^="/test_rqt_graph"]').count() == 0
        page.uncheck("#hide-debug")
        page.wait_for_selector('g.node[data-name^="/test_rqt_graph"]', timeout=10000)
        page.check("#hide-debug")

        # nodes-only view draws talker -> listener directly, as a live connection once swept
        page.select_option("#mode", "nodes")
        page.wait_for_selector(
            'path.edge:not(.pending)[data-source="/talker"][data-target="/listener"]',
            state="attached",
            timeout=10000,
        )
        page.select_option("#mode", "topics")

        listener.send_signal(signal.SIGINT)
        listener.wait(10)
        page.wait_for_selector('g.node[data-name="/listener"]', state="detached", timeout=20000)
        assert page.locator('g.node[data-name="/talker"]').count() == 1
