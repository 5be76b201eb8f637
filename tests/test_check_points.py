"""Check points along a path (gdnplan.trajopt.check_points): the interpolation weights."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from gdnplan.trajopt.check_points import _interpolation_matrix, _path_parameters


@given(st.lists(st.integers(1, 40), min_size=1, max_size=25))
def test_interpolation_matrix_is_the_linear_interpolation_of_its_definition(splits):
    """Row k of W·Q is waypoint t moved i / n_t of the way to waypoint t + 1 (the k-th check
    point, at path parameter t + i / n_t); the last row is the goal. W is sparse (two
    nonzeros per row) so that refined rounds do not grow a dense (K, T) array."""
    W = _interpolation_matrix(np.array(splits))
    T, K = len(splits) + 1, sum(splits) + 1
    assert W.shape == (K, T) and W.nnz <= 2 * K
    s = _path_parameters(np.array(splits))
    t = np.minimum(np.floor(s).astype(int), T - 2)
    expected = np.zeros((K, T))
    expected[np.arange(K), t] = 1 - (s - t)
    expected[np.arange(K), t + 1] += s - t
    np.testing.assert_allclose(W.toarray(), expected, atol=1e-12)
    np.testing.assert_array_equal(W.sum(axis=1).A1, 1.0)
