//! Nothing but the benchmarks in `benches/` (criterion): `cargo bench -p onebeacon-bench`.
