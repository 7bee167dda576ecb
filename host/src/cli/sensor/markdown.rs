//! The human form of `tirroi sensor`: header lines and three markdown tables.

use std::fmt::Write as _;

use super::report::{LevelChoice, SensorReport};

impl SensorReport {
    /// The human form: a few header lines and three markdown tables.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        // Writing into a String cannot fail.
        let _ = self.write_markdown(&mut s);
        s
    }

    fn write_markdown(&self, s: &mut String) -> std::fmt::Result {
        let m = &self.mapping;
        let n = &self.noise;
        writeln!(
            s,
            "tirroi sensor: the thermal camera model (response {}, emissivity {}, {} bits)\n",
            self.response.name(),
            self.emissivity,
            self.bits
        )?;
        writeln!(
            s,
            "Radiometry DN map (Eq. 17): F({} K) = {:.6e} W m^-2 -> DN 0, F({} K) = {:.6e} W m^-2 -> DN {}; gain a = {:.6e} DN per W m^-2, offset b = {:.6e} DN.\n",
            m.t_lo_k,
            m.f_min_w_m2,
            m.t_hi_k,
            m.f_max_w_m2,
            m.max_dn,
            m.gain_dn_per_w_m2,
            m.offset_dn
        )?;

        let level_note = match self.level {
            LevelChoice::Netd => format!(
                "NETD {} K at T_ref = {} K, dDN/dT = {:.6} DN/K",
                self.netd_k, self.t_ref_k, n.dn_per_k
            ),
            LevelChoice::PaperLiteral => "Eq. 16: 2470 ADU/V x v".to_owned(),
            LevelChoice::PaperVisible => {
                format!("Eq. 16 x full scale: 2470 ADU/V x v x {}", m.max_dn)
            }
        };
        writeln!(
            s,
            "Noise (Table 1 bolometer, RMS reading {}; sigma at level {}: {level_note}):\n",
            n.reading.name(),
            self.level.name()
        )?;
        writeln!(s, "| source | RMS [V] | sigma [DN] |")?;
        writeln!(s, "|---|---|---|")?;
        for (name, v, dn) in [
            ("johnson", n.johnson_v, n.johnson_dn),
            ("flicker (1/f)", n.flicker_v, n.flicker_dn),
            ("thermal", n.thermal_v, n.thermal_dn),
            ("total", n.total_v, n.total_dn),
        ] {
            writeln!(s, "| {name} | {v:.6e} | {dn:.6e} |")?;
        }
        writeln!(
            s,
            "\nTotal sigma of every level and its NETD equivalent (sigma / dDN/dT at {} K = {:.6} DN/K):\n",
            self.t_ref_k, n.dn_per_k
        )?;
        writeln!(s, "| level | total sigma [DN] | NETD equivalent [K] |")?;
        writeln!(s, "|---|---|---|")?;
        for row in &n.levels {
            let mark = if row.level == self.level {
                " (selected)"
            } else {
                ""
            };
            writeln!(
                s,
                "| {}{mark} | {:.6e} | {:.6e} |",
                row.level.name(),
                row.total_dn,
                row.netd_equivalent_k
            )?;
        }

        writeln!(
            s,
            "\nNoise voltage density (Eq. 15, Table 1 bolometer, bandwidth from f_L = 1 Hz):\n"
        )?;
        writeln!(s, "| bandwidth [Hz] | NVD [V Hz^-1/2] |")?;
        writeln!(s, "|---|---|")?;
        for row in &self.nvd {
            writeln!(
                s,
                "| {} | {:.6e} |",
                row.bandwidth_hz, row.nvd_v_per_sqrt_hz
            )?;
        }

        writeln!(
            s,
            "\nPer temperature (emissivity {}; sigma T^4/pi is the hand check: i = emissivity x sigma T^4/pi for --response flat):\n",
            self.emissivity
        )?;
        writeln!(
            s,
            "| T [K] | band radiance i [W m^-2 sr^-1] | F(T) [W m^-2] | radiometry DN | T_rad [K] | sigma T^4/pi [W m^-2 sr^-1] |"
        )?;
        writeln!(s, "|---|---|---|---|---|---|")?;
        let mut any_saturated = false;
        for row in &self.temperatures {
            let sat = if row.saturated {
                any_saturated = true;
                " (saturated)"
            } else {
                ""
            };
            writeln!(
                s,
                "| {} | {:.6e} | {:.6e} | {}{sat} | {:.4} | {:.6e} |",
                row.t_k,
                row.radiance_w_m2_sr,
                row.emissive_power_w_m2,
                row.dn,
                row.t_rad_k,
                row.sigma_t4_over_pi_w_m2_sr
            )?;
        }
        if any_saturated {
            writeln!(
                s,
                "\nSaturated: the temperature lies outside --range-k {},{} K, so its DN is clipped and T_rad is that of the clipped DN.",
                m.t_lo_k, m.t_hi_k
            )?;
        }
        Ok(())
    }
}
