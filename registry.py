"""One registry of named objects (a section law, a kinematics, a scheme, an orbit
method, an end component, a command's needs): each choice made by name is looked up
here, once, and an unknown name is refused once, with the list of names.

``error(key, name, why)`` builds the refusal (the registry's key: the scene key or the
option; ``why``: "must be one of (...)"), so each registry keeps its own exception type
(ParameterError for a scene key, SceneError for an option)."""

from __future__ import annotations

from typing import Callable, Generic, Iterable, Iterator, TypeVar

T = TypeVar("T")


def value_error(key: str, name, why: str) -> Exception:
    """The refusal of a registry below the parameters' errors: ``key = 'name': why``."""
    return ValueError(f"{key} = {name!r}: {why}")


class Registry(Generic[T]):
    """The objects of one kind by their ``name``, in their order of registration;
    ``listed`` shows the names in the refusal (tuple or list)."""

    def __init__(self, key: str, items: Iterable[T],
                 error: Callable[[str, object, str], Exception] = value_error,
                 listed: Callable = tuple):
        self.key, self._error, self._listed = key, error, listed
        self._items: dict[str, T] = {}
        for item in items:
            if item.name in self._items:
                raise ValueError(f"{key}: {item.name!r} is registered twice")
            self._items[item.name] = item

    def names(self) -> tuple[str, ...]:
        return tuple(self._items)

    def refusal(self, name) -> str | None:
        """Why ``name`` is none of the registered names (None: it is one)."""
        try:
            if name in self._items:
                return None
        except TypeError:  # unhashable: no name
            pass
        return f"must be one of {self._listed(self.names())}"

    def get(self, name) -> T:
        """The object of ``name``; any other name is refused once, with the list."""
        why = self.refusal(name)
        if why:
            raise self._error(self.key, name, why)
        return self._items[name]

    def __contains__(self, name) -> bool:
        return self.refusal(name) is None

    def __getitem__(self, name) -> T:
        return self._items[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def values(self):
        return self._items.values()

    def items(self):
        return self._items.items()
