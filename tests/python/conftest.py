"""pytest configuration for tests/python: the `oracle` marker.

A test marked `oracle` needs one of the heavy Python packages that only the full test run
installs (Pinocchio, PyBullet, Ray, Dask, SimPy: several GB with their dependencies) or
builds a wheel. `scripts/test --quick` installs requirements-quick.txt instead of
requirements-dev.txt and deselects them (`-m "not oracle"`); `scripts/test` runs them all.
"""


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "oracle: needs a heavy oracle package (pin, pybullet, ray, dask, simpy) or builds a wheel; "
        "scripts/test --quick leaves it out",
    )
