//! The options of `rins calibrate`, `rins data` and `rins import`: calibrations fitted from
//! samples, the public data sets fetched and checked, and recorded data sets converted.

use std::path::PathBuf;

use clap::{Args, Subcommand};

/// The calibrations `rins calibrate` fits.
#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// Magnetometer hard and soft iron from samples taken while the vehicle is turned through many
    /// orientations; prints the fit and a `[navigator.mag_calibration]` configuration fragment.
    Mag(CalibrateMagArgs),
}

/// Options of `rins calibrate mag`.
#[derive(Debug, Args)]
pub struct CalibrateMagArgs {
    /// CSV file: the output of `rins echo raw-mag --csv`, or a `mx_ut,my_ut,mz_ut` header and rows.
    pub file: PathBuf,
    /// Local field magnitude, µT (default: mean magnitude of the samples once the hard iron is
    /// removed).
    #[arg(long, allow_negative_numbers = true)]
    pub field_ut: Option<f64>,
    /// One JSON object on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
}

/// What `rins data` does.
#[derive(Debug, Subcommand)]
pub enum DataCommand {
    /// Clone each set's public git repository (one commit, only the files used) into
    /// DIR/.sources, convert it into the layout the evaluations read and write a PROVENANCE note
    /// beside it (source, commit, licence, what was converted, where the peer figures come
    /// from); a set already complete is left as it is.
    Fetch(DataFetchArgs),
    /// Which data sets are present in the recordings directory, which are incomplete or missing.
    List(DataListArgs),
}

/// Options of `rins data fetch`.
#[derive(Debug, Args)]
pub struct DataFetchArgs {
    /// The sets to fetch: quadrotor-4imu, pyshoe-vicon, xio-gait (default: all).
    #[arg(value_name = "SET")]
    pub sets: Vec<String>,
    /// Recordings directory (default: $RINS_DATA_DIR, else data/ at the top of the repository).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Fetch SET from another git repository (a mirror or a local copy) instead of its
    /// published one; repeatable.
    #[arg(long = "source", value_name = "SET=URL")]
    pub sources: Vec<String>,
    /// Clone the source again and build the set again even when it is complete, replacing its
    /// directory.
    #[arg(long)]
    pub force: bool,
}

/// Options of `rins data list`.
#[derive(Debug, Args)]
pub struct DataListArgs {
    /// Recordings directory (default: $RINS_DATA_DIR, else data/ at the top of the repository).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// The data sets `rins import` converts.
#[derive(Debug, Subcommand)]
pub enum ImportCommand {
    /// The four-IMU quadrotor flights (`<group>/path_<N>/IMU_k.csv`, `GT.csv`): one redundant
    /// block of every unit's triads, UAV profile, started in the air from the truth.
    Quadrotor(ImportArgs),
    /// The pyshoe foot-mounted walks (`*.csv` with the Vicon position), pedestrian profile.
    Pyshoe(ImportArgs),
}

/// Options of `rins import`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Directory of the data set.
    pub dir: PathBuf,
    /// Output directory: `<run>.mcap`, `<run>.toml` (configuration) and `<run>.json` (clock
    /// offsets, repairs, scales) per run, a flight's under its group directory.
    pub out: PathBuf,
    /// Replace output files that already exist (refused otherwise).
    #[arg(long)]
    pub force: bool,
    /// End with one JSON object instead of the summary.
    #[arg(long)]
    pub json: bool,
}
