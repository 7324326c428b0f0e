//! Runs the builder for the shipped robots and the fixtures, as a user's build script would.

use trocar_codegen::catalogue::Function;
use trocar_codegen::Builder;
use trocar_codegen::Real;

/// The outputs of the fused function `step_outputs` of the constrained modules.
const STEP_OUTPUTS: [Function; 5] = [
    Function::ConstrainedJacobian,
    Function::Manipulability,
    Function::ForwardKinematics,
    Function::PartialBodyJacobian,
    Function::ConstraintJacobianC,
];

fn main() {
    let robots = "../../runtime/model/robots";
    let mut b = Builder::new();
    for name in [
        "unidirectional",
        "bidirectional-zy",
        "bidirectional-zx",
        "dia10_like_zy",
        "dia10_like_zx",
        "panda-laparoscope",
        "iiwa-endoscope",
        "iiwa-link6",
    ] {
        b.robot(format!("{robots}/{name}.toml"));
    }
    b.robot("robots/rotated_rcm.toml");
    b.robot("robots/chain9_prismatic.toml");
    b.robot("robots/chain11_wide.toml");
    // A fused function in every module, its outputs in an order of its own (the agree tests
    // compare each with the reference).
    b.function("step_outputs", STEP_OUTPUTS);
    if let Err(e) = b.compile() {
        panic!("trocar-codegen: {e}");
    }
    // The fused functions' `f64` entry points with FMA chosen at run time
    // (`Builder::fma_at_run_time`), beside the modules above that have the same functions.
    let mut fma = Builder::new();
    fma.robot_as(format!("{robots}/panda-laparoscope.toml"), "panda_fma")
        .robot_as(format!("{robots}/dia10_like_zy.toml"), "dia10_fma")
        .function("step_outputs", STEP_OUTPUTS)
        .fma_at_run_time(true)
        .c_api(true);
    if let Err(e) = fma.compile() {
        panic!("trocar-codegen: {e}");
    }
    // Monomorphic variants (`--real f32|f64`).
    let mut f32b = Builder::new();
    f32b.robot_as(
        format!("{robots}/bidirectional-zy.toml"),
        "bidirectional_zy_f32",
    )
    .robot_as("robots/rotated_rcm.toml", "rotated_rcm_f32")
    .function("step_outputs", STEP_OUTPUTS)
    .real(Real::F32);
    if let Err(e) = f32b.compile() {
        panic!("trocar-codegen: {e}");
    }
    // The shipped scenes (`Builder::scene`): generic, and `three-ports` in f32.
    let scenes = "../../runtime/model/scenes";
    let mut sb = Builder::new();
    sb.scene(format!("{scenes}/three-ports.toml"))
        .scene(format!("{scenes}/dia10-dual.toml"));
    if let Err(e) = sb.compile() {
        panic!("trocar-codegen: {e}");
    }
    let mut sb32 = Builder::new();
    sb32.scene_as(format!("{scenes}/three-ports.toml"), "three_ports_f32")
        .real(Real::F32);
    if let Err(e) = sb32.compile() {
        panic!("trocar-codegen: {e}");
    }
    let mut f64b = Builder::new();
    f64b.robot_as(format!("{robots}/dia10_like_zx.toml"), "dia10_like_zx_f64")
        .real(Real::F64);
    if let Err(e) = f64b.compile() {
        panic!("trocar-codegen: {e}");
    }
    // Closed mechanisms: reduced Jacobian (8) and passive velocities (7) in closed form.
    let mechanisms = "../../runtime/model/robots/mechanisms";
    let mut mb = Builder::new();
    mb.mechanism(format!("{mechanisms}/four-bar.toml"))
        .mechanism(format!("{mechanisms}/planar-stewart.toml"));
    if let Err(e) = mb.compile() {
        panic!("trocar-codegen: {e}");
    }
    let mut mb32 = Builder::new();
    mb32.mechanism_as(format!("{mechanisms}/four-bar.toml"), "four_bar_f32")
        .real(Real::F32);
    if let Err(e) = mb32.compile() {
        panic!("trocar-codegen: {e}");
    }
    // `pose_and_jacobians_trig` as the four functions called in turn, the form written where one
    // program for all four would not be smaller (no shipped robot takes it): dia10_like with
    // that form forced, so that it compiles here and the agree tests check it.
    let desc = trocar_model::description::RobotDescription::preset("dia10_like_zy")
        .unwrap_or_else(|e| panic!("dia10_like_zy: {e}"));
    let d = trocar_codegen::derivation::derive(&desc).unwrap_or_else(|e| panic!("{e}"));
    let mut spec = trocar_codegen::lower::module_spec_with(
        &d,
        "dia10_like_zy_four_calls",
        &[trocar_codegen::catalogue::Fused::new(
            "step_outputs",
            STEP_OUTPUTS,
        )],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    spec.pose_and_jacobians = None;
    let text = trocar_codegen::emit::format_file(trocar_codegen::emit::module_tokens(
        &spec,
        Real::Generic,
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    std::fs::write(out.join("dia10_like_zy_four_calls.rs"), text)
        .unwrap_or_else(|e| panic!("writing dia10_like_zy_four_calls.rs: {e}"));

    // Generated code naming the runtime through a re-export (`Builder::runtime_path`).
    let mut reexport = Builder::new();
    reexport
        .robot_as(
            format!("{robots}/bidirectional-zy.toml"),
            "bidirectional_zy_reexport",
        )
        .mechanism_as(format!("{mechanisms}/four-bar.toml"), "four_bar_reexport")
        .runtime_path("crate::reexport::trocar");
    if let Err(e) = reexport.compile() {
        panic!("trocar-codegen: {e}");
    }

    // The C ABI (`Builder::c_api`): in f32, and generic (its C functions in f64), with the
    // controller step where the module has `Kinematics`.
    let mut c32 = Builder::new();
    c32.robot_as(format!("{robots}/panda-laparoscope.toml"), "panda_capi_f32")
        .real(Real::F32)
        .c_api(true);
    if let Err(e) = c32.compile() {
        panic!("trocar-codegen: {e}");
    }
    let mut cg = Builder::new();
    cg.robot_as(format!("{robots}/dia10_like_zy.toml"), "dia10_capi")
        .c_api(true);
    if let Err(e) = cg.compile() {
        panic!("trocar-codegen: {e}");
    }
    // Fused functions named like the wrappers' own parameters and locals (`q`, `p`, `out`,
    // `o0`, `params`; with `fma_at_run_time` the outputs' short names and `fk_fused`): the
    // wrappers call them through `self::`, so the module compiles (docs/RELIABILITY.md F28).
    let mut shadow = Builder::new();
    shadow
        .robot_as(format!("{robots}/unidirectional.toml"), "shadowing")
        .c_api(true)
        .fma_at_run_time(true);
    for name in [
        "q", "p", "out", "o0", "o1", "params", "fk", "fk_fused", "manip",
    ] {
        shadow.function(
            name,
            [Function::ForwardKinematics, Function::Manipulability],
        );
    }
    if let Err(e) = shadow.compile() {
        panic!("trocar-codegen: {e}");
    }
}
