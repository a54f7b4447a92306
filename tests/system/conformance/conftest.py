"""The conformance suite: one scenario suite, three backends (conformance_backends.py, test_scenarios.py).

Each backend is a fresh robot per test; the Python emulator's result of each scenario is the
reference, computed once per session (test_scenarios.reference).
"""
