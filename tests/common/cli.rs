//! The built binary from the command line (`assert_cmd`), and the scratch
//! paths the tests write its input and output to.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use std::path::PathBuf;

/// `ballpit`, as cargo built it for the tests.
pub fn ballpit() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("ballpit").unwrap()
}

/// `ballpit-NAME-PID` in the temp directory: a path of this test's own,
/// apart from other tests and runs. Not created.
pub fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("ballpit-{name}-{}", std::process::id()))
}
