pub mod diagnose;
pub mod gap_bench;
pub mod harness;
