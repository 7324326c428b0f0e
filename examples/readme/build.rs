// build.rs
fn main() {
    trocar_codegen::Builder::new()
        .robot("robots/arm.toml")
        .real(trocar_codegen::Real::F32)
        .compile()
        .unwrap();
}
