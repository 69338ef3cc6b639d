"""The rospy_tutorials programs shipped with ninjemys: ``rosrun rospy_tutorials talker.py`` and friends.

Each module is an executable node with ``main(argv) -> int`` written against the rospy API, so the
classic tutorial commands (talker/listener, add_two_ints server/client) work right after
``pip install``; the packages layer maps ``rosrun rospy_tutorials <name>`` to these modules.
"""

#: rosrun executable name -> module under ninjemys.tutorials
EXECUTABLES = {
    "talker": "talker",
    "talker.py": "talker",
    "listener": "listener",
    "listener.py": "listener",
    "add_two_ints_server": "add_two_ints_server",
    "add_two_ints_server.py": "add_two_ints_server",
    "add_two_ints_client": "add_two_ints_client",
    "add_two_ints_client.py": "add_two_ints_client",
}
