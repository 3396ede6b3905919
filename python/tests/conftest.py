"""pytest settings shared by the suites: the markers (run a marked set alone with -m NAME)."""


def pytest_configure(config):
    config.addinivalue_line("markers", "adapters: the third-party engine adapters' smoke runs (a few hundred ticks "
                                       "each, about a minute together; the full runs are `gauss6 reproduce engines`)")
