"""What a world tells its listeners after a step: contacts that began or ended, joints that broke.

``world.on_contact(callback)`` and ``world.on_joint_break(callback)`` register a listener; the
World hands each step's touching pairs (:func:`~deforma.physics.contact.pairs.group_pairs`)
and broken joints to :class:`Events`, which calls them. A listener that raises is reported
once, as a :class:`~deforma.checks.CallbackWarning` naming it and its error, and the step
stands (it has completed when listeners are called); the listener stays registered.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Callable

from ..checks import CallbackWarning
from .contact.pairs import ContactPair, contact_events


@dataclass(frozen=True)
class ContactEvent:
    """A pair of a body and a body or collider began or ended touching in a step.

    Attributes
    ----------
    kind : str
        ``"begin"``: they touch after this step and did not after the one before;
        ``"end"``: the reverse.
    pair : ContactPair
        The pair as it was this step (``"begin"``) or the last step it touched (``"end"``);
        ``pair.a`` is a body, ``pair.b`` a body or a collider.
    step : int
        ``world.step_count`` after the step.
    time : float
        ``world.time`` after the step (s).
    """

    kind: str
    pair: ContactPair
    step: int
    time: float

    @property
    def a(self) -> Any:
        """The pair's body."""
        return self.pair.a

    @property
    def b(self) -> Any:
        """What it touched: a body or a collider."""
        return self.pair.b


def _name(callback) -> str:
    return getattr(callback, "__qualname__", None) or getattr(callback, "__name__", None) or repr(callback)


class Events:
    """A world's listeners and the pairs that touched after its last step."""

    def __init__(self):
        self.contact: list[Callable] = []
        self.joint_break: list[Callable] = []
        self.touching: dict = {}  # (id(a), id(b)) -> ContactPair after the last step
        self._said: set = set()  # ids of listeners whose error was reported

    @staticmethod
    def checked(callback, method: str) -> Callable:
        """``callback`` if it can be called, else ``ValueError`` in one line."""
        if not callable(callback):
            raise ValueError(f"{method} takes a function to call, got {callback!r} ({type(callback).__name__})")
        return callback

    @property
    def listening(self) -> bool:
        """Whether anyone listens for contacts (the World then groups the pairs every step)."""
        return bool(self.contact)

    def remove(self, callback) -> None:
        """Stop calling ``callback`` (for contacts and joint breaks); ``ValueError`` if it was
        never registered."""
        if not any(c is callback for c in (*self.contact, *self.joint_break)):
            raise ValueError(f"{_name(callback)} is not a listener of this world (on_contact, on_joint_break)")
        self.contact = [c for c in self.contact if c is not callback]
        self.joint_break = [c for c in self.joint_break if c is not callback]
        if not self.contact:
            self.touching = {}

    def contacts(self, pairs: dict, step: int, time: float) -> None:
        """Compare the pairs touching now with those after the last step and call the contact
        listeners: the ends first, then the begins."""
        begun, ended = contact_events(self.touching, pairs)
        self.touching = pairs
        for pair in ended:
            self._call(self.contact, ContactEvent("end", pair, step, time))
        for pair in begun:
            self._call(self.contact, ContactEvent("begin", pair, step, time))

    def joints_broken(self, joints) -> None:
        """Call the joint-break listeners with each joint broken this step."""
        for j in joints:
            self._call(self.joint_break, j)

    def _call(self, listeners, arg) -> None:
        for callback in list(listeners):
            try:
                callback(arg)
            except Exception as error:  # a listener's bug must not undo a completed step
                if id(callback) not in self._said:
                    self._said.add(id(callback))
                    warnings.warn(f"listener {_name(callback)} raised {type(error).__name__}: {error} (the step "
                                  "completed; said once per listener)", CallbackWarning, stacklevel=4)
