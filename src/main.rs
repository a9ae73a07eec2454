use clap::Parser;

#[derive(Parser)]
struct Cli {
    #[arg(long, default_value = "32,64,128,256")]
    sizes: String,
    #[arg(long, default_value_t = 5)]
    runs: usize,
    #[arg(long, default_value_t = 50)]
    frames: u32,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    for s in cli.sizes.split(',') {
        let n: usize = s.trim().parse()?;
        let r = emilion::bench::bench_hang(n, cli.frames, cli.runs)?;
        println!("{}", serde_json::to_string(&r)?);
    }
    Ok(())
}
