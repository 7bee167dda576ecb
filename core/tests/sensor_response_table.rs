//! The committed const table `core/src/sensor/response_table.rs` against its source,
//! `core/data/hayabusa2-tir/response.txt`: every sample equal, exactly, and nothing but
//! zeros outside the stored span, so the two can never drift apart and the cut loses
//! nothing (rerun scripts/reference/response_table.py when the data file changes).

use tirroi_core::sensor::response_table::{FIRST_CENTI_UM, RESPONSE_MICRO, SAMPLES};
use tirroi_core::sensor::{CameraResponse, TabulatedResponse};

const DATA: &str = include_str!("../data/hayabusa2-tir/response.txt");

/// "0.909000" → 909000, "-0.000026" → −26: the decimal exactly, without a float.
fn micro(text: &str) -> i64 {
    let (sign, digits) = match text.strip_prefix('-') {
        Some(rest) => (-1, rest),
        None => (1, text),
    };
    let (whole, frac) = digits.split_once('.').expect("a decimal point");
    assert_eq!(frac.len(), 6, "six decimals: {text}");
    sign * (whole.parse::<i64>().unwrap() * 1_000_000 + frac.parse::<i64>().unwrap())
}

/// (wavelength in 0.01 µm, R in 1e-6) of every line of the data file.
fn data_rows() -> Vec<(i64, i64)> {
    DATA.lines()
        .map(|line| {
            let cols: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(cols.len(), 2, "two columns: {line:?}");
            let lambda = micro(cols[0]);
            assert_eq!(lambda % 10_000, 0, "on the 0.01 um grid: {line:?}");
            (lambda / 10_000, micro(cols[1]))
        })
        .collect()
}

#[test]
fn generated_table_equals_the_data_file() {
    let rows = data_rows();
    assert_eq!(rows.len(), 2000);
    for (i, &(c, _)) in rows.iter().enumerate() {
        assert_eq!(
            c,
            i as i64,
            "line {}: the grid is 0.00, 0.01, ... um",
            i + 1
        );
    }
    let first = FIRST_CENTI_UM as usize;
    for (i, &(c, r)) in rows.iter().enumerate() {
        if (first..first + SAMPLES).contains(&i) {
            assert_eq!(
                i64::from(RESPONSE_MICRO[i - first]),
                r,
                "{:.2} um differs from the data file",
                c as f64 / 100.0
            );
        } else {
            assert_eq!(
                r,
                0,
                "{:.2} um: non-zero outside the stored span",
                c as f64 / 100.0
            );
        }
    }
    // The span is tight: its ends are the zeros next to the first and last non-zero sample.
    assert_eq!(RESPONSE_MICRO[0], 0);
    assert_ne!(RESPONSE_MICRO[1], 0);
    assert_eq!(RESPONSE_MICRO[SAMPLES - 1], 0);
    assert_ne!(RESPONSE_MICRO[SAMPLES - 2], 0);
}

#[test]
fn response_at_the_samples_is_the_data_file_decimal() {
    let table = TabulatedResponse::HAYABUSA2_TIR;
    let r = CameraResponse::default();
    for (c, line) in DATA.lines().enumerate() {
        let cols: Vec<&str> = line.split_whitespace().collect();
        let want: f64 = cols[1].parse().unwrap();
        let lambda: f64 = cols[0].parse().unwrap();
        let got = r.at(lambda);
        // At a sample, (λ − λ_0)/Δλ is an integer only to ~1e-13 in f64, so the
        // neighbour keeps a weight of that size.
        assert!((got - want).abs() < 1e-13, "{lambda} um: {got} vs {want}");
        if (FIRST_CENTI_UM as usize..FIRST_CENTI_UM as usize + SAMPLES).contains(&c) {
            assert_eq!(
                table.sample(c - FIRST_CENTI_UM as usize),
                want,
                "{lambda} um"
            );
        }
    }
}
