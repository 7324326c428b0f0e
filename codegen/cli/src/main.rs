//! The `trocar` command line; see [`trocar_cli`].

fn main() {
    std::process::exit(trocar_cli::main());
}
