"""A frozen dataclass whose hash is computed once (the expression tree's nodes)."""
from __future__ import annotations


def hash_cached(cls):
    """A frozen dataclass node whose hash is computed once: a network's expressions
    share subtrees, and the generated hash walks the whole tree on every dictionary
    lookup (f1_barr3: 6.4 million hash calls in one run). The cached value is not
    pickled: string hashes differ between processes."""
    generated = cls.__hash__

    def __hash__(self):
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = generated(self)
            object.__setattr__(self, "_hash", cached)
        return cached

    def __getstate__(self):
        return {k: v for k, v in self.__dict__.items() if k != "_hash"}

    cls.__hash__, cls.__getstate__ = __hash__, __getstate__
    return cls
