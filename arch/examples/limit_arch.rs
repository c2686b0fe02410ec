//! Limit analysis of the reference arch under a point load on voussoir 5: collapse load,
//! mechanism, ParaView frames of the mechanism.
//! `cargo run --release --example limit_arch -- --help`. See [`voussoir_arch::cli::arch_limit`].

fn main() {
    voussoir_arch::cli::main::<voussoir_arch::cli::arch_limit::LimitArgs>();
}
