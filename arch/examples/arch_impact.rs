//! The six drop-weight impact tests of the reference arch:
//! `cargo run --release --example arch_impact -- --help`. See [`voussoir_arch::cli::arch_impact`].

fn main() {
    voussoir_arch::cli::main::<voussoir_arch::cli::arch_impact::ImpactOptions>();
}
