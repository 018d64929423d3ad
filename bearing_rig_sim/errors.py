"""User-facing error classes.

Every error a user can cause (bad configuration, bad command-line value, unreadable bag, bad
set-point) derives from :class:`RigError`. The command line prints such errors as one readable
line and exits with status 2; anything else is a bug and keeps its traceback.
"""

from __future__ import annotations


class RigError(Exception):
    """Base class of the errors a user can cause and fix; the message says what is wrong."""
