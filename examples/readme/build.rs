// build.rs
fn main() {
    trocar_codegen::Builder::new()
        .robot("robots/arm.toml")
        .real(trocar_codegen::Scalar::F32)
        .compile()
        .unwrap();
}
