"""The numpy filters of :mod:`contactlab._filters`, under the name the diagnosis modules and
tests have used."""

from .._filters import (  # noqa: F401
    decimate,
    first_order_response,
    hermite_coefficients,
    hilbert,
    savgol_coeffs,
    savgol_filter,
    uniform_filter1d,
    welch,
)
