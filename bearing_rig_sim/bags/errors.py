"""Errors and warnings of the recording package.

:class:`BagError` is raised for anything a user can cause and fix (a path that is not a bag, an
unreadable ``metadata.yaml``, a topic written before it was added); the command line prints it as
one line. :class:`BagWarning` reports a problem the reader or the repair worked around (a damaged
chunk skipped, a topic whose type is unknown): the data that could be read is still returned.
"""

from __future__ import annotations

from bearing_rig_sim.errors import RigError


class BagError(RigError):
    """A bag cannot be written, read or repaired as asked; the message names the file and the problem."""


class BagWarning(UserWarning):
    """A bag was read only in part (damaged chunk, unknown message type, stale metadata)."""
