"""Errors and warnings of the recording package: :class:`BagError` for what a user can cause and fix
(printed as one line), :class:`BagWarning` for damage worked around (what could be read is returned)."""

from __future__ import annotations

from bearing_rig_sim.errors import RigError


class BagError(RigError):
    """A bag cannot be written, read or repaired as asked; the message names the file and the problem."""


class BagWarning(UserWarning):
    """A bag was read only in part (damaged chunk, unknown message type, stale metadata)."""
