//! Benchmark harness (see the `harness` submodules).
