//! The `trocar` command line; see [`trocar_codegen::cli`].

fn main() {
    std::process::exit(trocar_codegen::cli::main());
}
