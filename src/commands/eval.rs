//! `rins eval fdi DIR`: loads the configuration, runs [`rins_eval::fdi::evaluate`] with a
//! progress bar and prints the report.

use anyhow::Result;
use rins_eval::fdi::{FdiRequest, evaluate, to_table};

use crate::cli::EvalFdiArgs;
use crate::config;

pub fn run_fdi(args: &EvalFdiArgs) -> Result<()> {
    let cfg = config::load(args.config.as_deref())?;
    let request = FdiRequest {
        dir: args.dir.clone(),
        trials: args.trials.clone(),
        fdi: cfg.fusion.fdi.clone(),
        lsb: [cfg.device.gyro_lsb_rps(), cfg.device.accel_lsb_mps2()],
    };
    let mut bar = super::progress::Progress::new("eval fdi");
    let report = evaluate(&request, &mut |done, total| bar.set(done, total))?;
    bar.finish();
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", to_table(&report));
    }
    Ok(())
}
