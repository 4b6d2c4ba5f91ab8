//! The `dvr` binary: the command line of the library beside it (`src/cli.rs`).

fn main() {
    dvr::cli::main()
}
