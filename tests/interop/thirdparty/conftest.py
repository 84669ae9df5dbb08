# Vendored third-party test suites: test data for tests/interop/test_suites_over_motorbus.py,
# which runs them in child pytest processes.  The project's own pytest run must not collect them.
collect_ignore_glob = ["*"]
