//! `czid gap-bench` (being written).
#[derive(Debug, Clone, clap::Args)]
pub struct GapBenchArgs {}
pub fn run(_: &GapBenchArgs) -> Result<(), czid_core::CzError> {
    Ok(())
}
