"""Bash completion for every ninjemys command: ``ninjemys.bash`` (see ninjemys.tools.complete).

The file's path lives here, with the data, so that both the completion command (a tool) and the
workspace set-up scripts (``ninjemys.packages``, a lower layer) can name it.
"""

import os

#: the completion script that ``setup.bash`` sources and ``ninjemys-complete --bash`` prints
BASH_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ninjemys.bash")
