# SPDX-License-Identifier: MIT
"""Short TypeErrors for calls into the compiled module.

pybind11 answers a misspelled keyword or a wrong argument type with every overload's full
signature and a dump of the values passed (a whole array). The wrappers installed here keep
the call as it is and, on such an error only, raise a TypeError that names the unknown keyword
(with the closest valid one) or the expected signature and the types that were passed.
"""
import difflib
import functools
import inspect
import re
import typing

_PYBIND = re.compile(r"incompatible (function|constructor) arguments")
_OVERLOAD = re.compile(r"^\s*\d+\. (?:[\w.]+)?\((.*)\)(?: -> .*)?$", re.M)


def _names(params: str) -> typing.List[str]:
    return [m.group(1) for m in re.finditer(r"(?:^|, )\*{0,2}(\w+)(?=: |, |$| =)", params) if m.group(1) != "self"]


def _short(name: str, message: str, args: typing.Sequence[typing.Any],
           kwargs: typing.Dict[str, typing.Any]) -> str:
    overloads = _OVERLOAD.findall(message)
    valid: typing.Set[str] = set()
    for params in overloads:
        valid.update(_names(params))
    unknown = [k for k in kwargs if k not in valid]
    if unknown and valid:
        k = unknown[0]
        close = difflib.get_close_matches(k, sorted(valid), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        return (f"{name}() got an unexpected keyword argument {k!r}{hint} "
                f"(its arguments: {', '.join(n for n in _names(overloads[0]))})")
    given = ", ".join([type(a).__name__ for a in args] + [f"{k}={type(v).__name__}" for k, v in kwargs.items()])
    expected = " or ".join(f"{name}({p})" for p in overloads[:2]) or name + "(...)"
    return f"{name}(): the arguments do not match {expected}; got ({given})"


def _wrap(fn: typing.Any, name: str, skip_self: bool = False) -> typing.Any:
    @functools.wraps(fn)
    def call(*args: typing.Any, **kwargs: typing.Any) -> typing.Any:
        try:
            return fn(*args, **kwargs)
        except TypeError as e:
            if not _PYBIND.search(str(e)):
                raise
            shown = args[1:] if skip_self else args
            raise TypeError(_short(name, str(e), shown, kwargs)) from None

    return call


def install(*modules: typing.Any) -> None:
    """Wraps the functions, constructors and methods of the compiled `modules`."""
    for mod in modules:
        for name, value in list(vars(mod).items()):
            if name.startswith("_"):
                continue
            if inspect.isclass(value) and not issubclass(value, BaseException):
                _install_class(value)
            elif type(value).__name__ == "builtin_function_or_method":
                setattr(mod, name, _wrap(value, name))


def _install_class(cls: typing.Any) -> None:
    for attr, value in list(vars(cls).items()):
        if attr.startswith("_") and attr != "__init__":
            continue
        label = cls.__name__ if attr == "__init__" else f"{cls.__name__}.{attr}"
        if isinstance(value, staticmethod):
            setattr(cls, attr, staticmethod(_wrap(value.__func__, label)))
        elif type(value).__name__ in ("instancemethod", "builtin_function_or_method"):
            if type(value).__name__ == "builtin_function_or_method":  # a pybind11 static method
                setattr(cls, attr, staticmethod(_wrap(value, label)))
            else:
                setattr(cls, attr, _wrap(value, label, skip_self=True))
