// build.rs
fn main() {
    trocar_codegen::Builder::new()
        .robot("robots/arm.toml")
        .real(trocar_codegen::Scalar::F32)
        .checks(true) // `arm::Checks` for the crate's tests, behind #[cfg(test)]
        .evidence(500) // checked now; the largest errors in the module's documentation
        .compile()
        .unwrap();
}
