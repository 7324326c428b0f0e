// build.rs
use trocar_codegen::catalogue::Function::{
    ConstrainedJacobian, ForwardKinematics, PartialBodyJacobian,
};

fn main() {
    trocar_codegen::Builder::new()
        .robot("robots/arm.toml")
        .real(trocar_codegen::Real::F32)
        .checks(true) // `arm::Checks` for the crate's tests, behind #[cfg(test)]
        .evidence(500) // checked now; the largest errors in the module's documentation
        // one function, one program: g_0e, J^B_0i and J^r sharing their common values
        .function(
            "tip_and_jacobians",
            [ForwardKinematics, PartialBodyJacobian, ConstrainedJacobian],
        )
        .compile()
        .unwrap();
}
