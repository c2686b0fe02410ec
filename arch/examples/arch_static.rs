//! The quasi-static test of the reference arch and the paper's parameter studies:
//! `cargo run --release --example arch_static -- --help`. See [`voussoir_arch::cli::arch_static`].

fn main() {
    voussoir_arch::cli::main::<voussoir_arch::cli::arch_static::StaticOptions>();
}
