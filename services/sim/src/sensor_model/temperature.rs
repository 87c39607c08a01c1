//! Module temperatures: each sensor sits at the nominal temperature plus a fixed offset and warms up
//! with a first-order approach, `T_j(t) = T_nom + o_j + ΔT_w (1 − e^{−t/τ_w})`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Temperature slots in a frame.
pub const TEMPERATURE_SLOTS: usize = ipc_types::MAX_TEMPERATURES;

#[derive(Debug, Clone)]
pub(crate) struct TemperatureModel {
    count: usize,
    nominal_c: f64,
    offset_c: [f64; TEMPERATURE_SLOTS],
    warmup_c: f64,
    warmup_tau_s: f64,
}

impl TemperatureModel {
    /// Offsets are drawn from `rng` for every slot, used or not, to keep the stream layout fixed.
    pub fn new(
        count: usize,
        nominal_c: f64,
        spread_c: f64,
        warmup_c: f64,
        warmup_tau_s: f64,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        let mut offset_c = [0.0; TEMPERATURE_SLOTS];
        for o in &mut offset_c {
            *o = spread_c * rng.sample::<f64, _>(StandardNormal);
        }
        Self {
            count: count.min(TEMPERATURE_SLOTS),
            nominal_c,
            offset_c,
            warmup_c,
            warmup_tau_s,
        }
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// Each sensor's temperature above the nominal (reference) temperature at `t_s`, °C.
    pub fn delta_c(&self, t_s: f64) -> [f64; TEMPERATURE_SLOTS] {
        let warm = self.warmup_c * (1.0 - (-t_s / self.warmup_tau_s).exp());
        self.offset_c.map(|o| o + warm)
    }

    /// Temperatures in hundredths of a degree Celsius; unused slots read 0.
    pub fn centi_c(&self, delta_c: &[f64; TEMPERATURE_SLOTS], out: &mut [i16; TEMPERATURE_SLOTS]) {
        for (i, (o, d)) in out.iter_mut().zip(delta_c).enumerate() {
            *o = if i < self.count {
                to_centi_c(self.nominal_c + d)
            } else {
                0
            };
        }
    }
}

/// °C → hundredths of a degree, saturated to the i16 range.
pub(crate) fn to_centi_c(celsius: f64) -> i16 {
    // `as` saturates (and maps NaN to 0), which is the intended clamp.
    (celsius * 100.0).round() as i16
}
