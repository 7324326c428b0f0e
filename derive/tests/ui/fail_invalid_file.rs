use trocar_derive::constrained_robot;

// CARGO_MANIFEST_DIR is trybuild's project dir, $WORKSPACE/target/tests/trybuild/trocar-derive.
#[constrained_robot(file = "../../../../derive/tests/ui/robots/bad_axis.toml")]
struct Arm;

fn main() {}
