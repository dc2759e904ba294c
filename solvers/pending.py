"""A value being made elsewhere (:class:`Pending`): in a helper process
(:mod:`gatetherm.solvers.helper`), or later, where it is first needed."""
from __future__ import annotations

from typing import Any, Callable


class Pending:
    """A value being made elsewhere: :meth:`result` waits for it (once), :meth:`done` asks."""

    def __init__(self, wait: Callable[[], Any], poll: Callable[[], bool] = lambda: True):
        self._wait, self._poll, self._value, self._has = wait, poll, None, False

    @classmethod
    def of(cls, value) -> "Pending":
        """A value made already."""
        p = cls(lambda: value)
        p._value, p._has = value, True
        return p

    def done(self) -> bool:
        return self._has or self._poll()

    def result(self):
        if not self._has:
            self._value, self._has = self._wait(), True
            self._wait = self._poll = None
        return self._value

    def then(self, f: Callable[[Any], Any]) -> "Pending":
        """The pending ``f(value)``."""
        return Pending(lambda: f(self.result()), self.done)

    def __reduce__(self):  # pickled (to another process) as the value itself
        return _identity, (self.result(),)


def _identity(value):
    return value
