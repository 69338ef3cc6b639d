"""Exception mapping for the facade: ninjemys errors become rospy's, dynamic_reconfigure's stay."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from ninjemys.dynamic_reconfigure.errors import DynamicReconfigureException
from ninjemys.errors import NinjemysError


@contextmanager
def mapped() -> Iterator[None]:
    try:
        yield
    except DynamicReconfigureException:
        raise
    except NinjemysError as exc:
        from rospy.exceptions import translate

        raise translate(exc) from None
