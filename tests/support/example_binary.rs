//! Where the built examples are, for the tests that run them (`tests/examples_cli.rs`,
//! `arch/tests/cli.rs`): both crates' examples land in the workspace's `target/<profile>/examples/`.

use std::path::{Path, PathBuf};

/// The built example `name` (beside this test's `deps/` folder).
pub fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    let path = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>")
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.exists(),
        "{} is not built: run `cargo build --release --examples` (cargo test builds it)",
        path.display()
    );
    path
}
