//! The `dhcd` command line: `collide`, `experiment`, `self`, `scene`.

mod cmd;

fn main() {
    std::process::exit(cmd::run());
}
