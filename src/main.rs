//! The `dhcd` command line: `collide`, `experiment`, `self`, `scene`.

mod cli;

fn main() {
    std::process::exit(cli::run());
}
