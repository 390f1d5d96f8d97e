"""The test suite, one sub-package per layer of ``speedplan`` (docs/architecture.md)."""
