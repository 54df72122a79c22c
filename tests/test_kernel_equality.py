"""SafeKernel equality: two kernels of the same input compare equal (no ValueError
from comparing numpy fields), also after a pickle round trip; the wall time is not
compared; a different F, input or kernel compares unequal."""

import pickle

import numpy as np

import rescon


def _cloud(seed: int = 0, n: int = 12, d: int = 2) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, d))


def test_same_input_twice_compares_equal():
    X = _cloud()
    K1, K2 = rescon.safe_kernel(X, 2), rescon.safe_kernel(X, 2)
    assert K1 == K2 and not (K1 != K2)


def test_pickle_round_trip_compares_equal():
    K = rescon.safe_kernel(_cloud(1, 20, 3), 3)
    assert pickle.loads(pickle.dumps(K)) == K


def test_different_F_input_or_kind_compare_unequal():
    X = _cloud(2)
    K = rescon.safe_kernel(X, 2)
    assert K != rescon.safe_kernel(X, 3)
    Y = X.copy()
    Y[0, 0] = np.nextafter(Y[0, 0], np.inf)
    assert K != rescon.safe_kernel(Y, 2)
    assert K != "kernel" and K != None  # noqa: E711


def test_empty_kernels_compare_by_input():
    X = _cloud(3, 6, 2)
    E1, E2 = rescon.safe_kernel(X, 4), rescon.safe_kernel(X, 4)
    assert E1.is_empty and E1 == E2


def test_equal_kernels_hash_alike():
    X = _cloud(4)
    K1, K2 = rescon.safe_kernel(X, 2), rescon.safe_kernel(X, 2)
    assert hash(K1) == hash(K2) and len({K1, K2}) == 1


def test_signed_zero_inputs_are_equal_and_hash_alike():
    X = _cloud(5)
    X[0] = 0.0
    Y = X.copy()
    Y[0] = -0.0
    K1, K2 = rescon.safe_kernel(X, 2), rescon.safe_kernel(Y, 2)
    assert K1 == K2 and hash(K1) == hash(K2)
