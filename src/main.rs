fn main() {
    eprintln!("dhcd: CLI not wired yet");
    std::process::exit(2);
}
