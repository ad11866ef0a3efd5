"""numba drops a store into an array taken from a named tuple inside a prange body (the 2026-12-02 inlining entry).

    python dropped_store_repro.py   ->  one line per variant: whether the stores arrived

The inlined stress update of g2p_update did `stress = SP.stress` inside the prange body and stored into it last;
numba's parallel dead-code elimination counts a named tuple's fields as no alias of the arguments (the tuple is
immutable), so a store the body does not read back is removed. numba issues 7135, 10338."""
from typing import NamedTuple

import numba
import numpy as np
from numba import njit, prange


class S(NamedTuple):
    a: np.ndarray


@njit(inline="always")
def put_through_tuple(T, i):
    arr = T.a  # taken from the tuple inside the caller's prange body once inlined
    arr[i] = 1.0


@njit(inline="always")
def put_into(arr, i):
    arr[i] = 1.0


@njit(parallel=True)
def via_tuple(T):
    for i in prange(T.a.shape[0]):
        put_through_tuple(T, i)


@njit(parallel=True)
def via_array(T):
    arr = T.a  # taken before the prange
    for i in prange(arr.shape[0]):
        put_into(arr, i)


for f in (via_tuple, via_array):
    T = S(np.zeros(8))
    f(T)
    print(f"numba {numba.__version__}, {f.__name__}: {'stored' if T.a.sum() == 8 else 'STORES DROPPED'}")
