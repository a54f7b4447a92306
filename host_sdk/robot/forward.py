"""`part_method`: a Robot method that is a part's method, so `robot.drive(...)` reads as one flat
API while `Driving` owns the state behind it. Type checkers see the part's signature."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, Concatenate, Generic, ParamSpec, TypeVar, overload

P = ParamSpec("P")
R = TypeVar("R")
Part = TypeVar("Part")


class part_method(Generic[Part, P, R]):
    """`drive = part_method("_driving", Driving.drive)`: `robot.drive` is `robot._driving.drive`."""

    def __init__(self, attribute: str, method: Callable[Concatenate[Part, P], R]) -> None:
        self._attribute = attribute
        self._method = method

        @functools.wraps(method)
        def on_owner(owner: Any, /, *args: P.args, **kwargs: P.kwargs) -> R:
            return method(getattr(owner, attribute), *args, **kwargs)

        self._on_owner: Callable[Concatenate[Any, P], R] = on_owner
        self.__doc__ = method.__doc__

    @overload
    def __get__(self, obj: None, owner: type) -> Callable[Concatenate[Any, P], R]: ...
    @overload
    def __get__(self, obj: object, owner: type) -> Callable[P, R]: ...
    def __get__(self, obj: object | None, owner: type) -> Any:
        if obj is None:  # Robot.drive: a function of a robot, documented as the part's
            return self._on_owner
        return getattr(getattr(obj, self._attribute), self._method.__name__)
