//! The `trocar` command line (SPEC §5).

/// Runs the command line with the process arguments and returns the exit code.
pub fn main() -> i32 {
    0
}
