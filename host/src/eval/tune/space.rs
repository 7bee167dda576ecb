//! The tuning space of each detector: the grid of parameter sets [`grid`] scores
//! first and the ladders [`neighbours`] refines on. The parameter sets themselves are
//! the core registry's [`Params`]; a detector without a space here (a new registry
//! entry) is tuned over its defaults and the two box rules only.

use tirroi_core::roi::Params;
use tirroi_core::roi::adaptive::Adaptive;
use tirroi_core::roi::auto::Auto;
use tirroi_core::roi::dog::Dog;
use tirroi_core::roi::wge::Wge;
use tirroi_core::{BoxRule, Method};

/// The core's default parameters of `method` with box rule `rule`.
pub fn defaults(method: Method, rule: BoxRule) -> Params {
    let mut p = method.default_params();
    p.set_box_rule(rule);
    p
}

/// Whether the core accepts these parameters.
pub fn is_valid(p: &Params) -> bool {
    p.validate().is_ok()
}

fn other_rule(rule: BoxRule) -> BoxRule {
    match rule {
        BoxRule::AllForeground => BoxRule::LargestComponent,
        BoxRule::LargestComponent => BoxRule::AllForeground,
    }
}

/// The refinement neighbours of `p`: one ladder step down and up of each coordinate,
/// and the other box rule; only valid sets.
pub fn neighbours(p: &Params) -> Vec<Params> {
    let mut out = Vec::new();
    let mut flipped = *p;
    flipped.set_box_rule(other_rule(p.box_rule()));
    if flipped != *p {
        out.push(flipped);
    }
    match *p {
        Params::Adaptive(p) => {
            for block in steps(&BLOCK_LADDER, p.block) {
                out.push(Params::Adaptive(Adaptive { block, ..p }));
            }
            for offset_dn in steps(&OFFSET_LADDER, p.offset_dn) {
                out.push(Params::Adaptive(Adaptive { offset_dn, ..p }));
            }
        }
        Params::Wge(p) => {
            for drop_fraction in steps(&DROP_LADDER, p.drop_fraction) {
                out.push(Params::Wge(Wge { drop_fraction, ..p }));
            }
            for min_gradient in steps(&GRADIENT_LADDER, p.min_gradient) {
                out.push(Params::Wge(Wge { min_gradient, ..p }));
            }
        }
        Params::Dog(p) => {
            for sigma0_px in steps(&SIGMA0_LADDER, p.sigma0_px) {
                out.push(Params::Dog(Dog { sigma0_px, ..p }));
            }
            for sigma_ratio in steps(&RATIO_LADDER, p.sigma_ratio) {
                out.push(Params::Dog(Dog { sigma_ratio, ..p }));
            }
            for levels in [p.levels.wrapping_sub(1), p.levels.saturating_add(1)] {
                out.push(Params::Dog(Dog { levels, ..p }));
            }
            for min_response_dn in steps(&RESPONSE_LADDER, p.min_response_dn) {
                out.push(Params::Dog(Dog {
                    min_response_dn,
                    ..p
                }));
            }
        }
        Params::Auto(p) => {
            for coarse_sigma in steps(&AUTO_SIGMA_LADDER, p.coarse_sigma) {
                out.push(Params::Auto(Auto { coarse_sigma, ..p }));
            }
            for fine_sigma in steps(&AUTO_SIGMA_LADDER, p.fine_sigma) {
                out.push(Params::Auto(Auto { fine_sigma, ..p }));
            }
        }
        // Otsu (the box rule is its only coordinate) and any detector without
        // ladders here.
        _ => {}
    }
    out.retain(is_valid);
    out
}

/// The nearest ladder values below and above `v` (either may be missing).
fn steps<T: PartialOrd + Copy>(ladder: &[T], v: T) -> Vec<T> {
    let below = ladder.iter().rev().find(|&&x| x < v).copied();
    let above = ladder.iter().find(|&&x| x > v).copied();
    below.into_iter().chain(above).collect()
}

/// Refinement ladder of the adaptive `block` (odd pixels).
pub const BLOCK_LADDER: [u16; 29] = [
    3, 5, 7, 9, 11, 13, 15, 17, 21, 25, 29, 33, 37, 41, 47, 53, 61, 71, 81, 91, 101, 111, 121, 141,
    161, 181, 201, 225, 249,
];
/// Refinement ladder of the adaptive `offset_dn` (DN).
pub const OFFSET_LADDER: [i32; 25] = [
    -256, -128, -64, -32, -16, 0, 8, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024,
    1536, 2048, 3072, 4096, 6144,
];
/// Refinement ladder of the WGE `drop_fraction`.
pub const DROP_LADDER: [f32; 19] = [
    0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.93, 0.95, 0.96, 0.97, 0.975, 0.98, 0.985, 0.99, 0.993, 0.995,
    0.997, 0.998, 0.999,
];
/// Refinement ladder of the WGE `min_gradient` (Prewitt L1 DN).
pub const GRADIENT_LADDER: [u32; 25] = [
    0, 8, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144,
    8192, 12288, 16384, 24576, 32768,
];
/// Refinement ladder of the DoG `sigma0_px`.
pub const SIGMA0_LADDER: [f32; 11] = [1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0];
/// Refinement ladder of the DoG `sigma_ratio`.
pub const RATIO_LADDER: [f32; 7] = [1.2, 1.3, 1.4, 1.6, 1.8, 2.0, 2.4];
/// Refinement ladder of the DoG `min_response_dn` (DN).
pub const RESPONSE_LADDER: [u32; 17] = [
    16, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144,
];

/// Refinement ladder of `auto`'s `coarse_sigma` and `fine_sigma` (noise units).
pub const AUTO_SIGMA_LADDER: [u16; 11] = [3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32];

/// The candidate grid of `method` (see the module documentation): every set of the
/// grid with the largest-component rule, then every set with the all-foreground rule;
/// the core defaults are among them; only valid sets.
pub fn grid(method: Method) -> Vec<Params> {
    let mut base = Vec::new();
    match method {
        Method::Adaptive => {
            for block in [11, 21, 41, 61, 81, 121, 161] {
                for offset_dn in [0, 32, 64, 128, 256, 512, 1024, 2048, 4096] {
                    base.push(Params::Adaptive(Adaptive {
                        block,
                        offset_dn,
                        ..Adaptive::default()
                    }));
                }
            }
        }
        Method::Wge => {
            for drop_fraction in [0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998] {
                for min_gradient in [0, 48, 128, 256, 512, 1024, 2048, 4096, 8192] {
                    base.push(Params::Wge(Wge {
                        drop_fraction,
                        min_gradient,
                        ..Wge::default()
                    }));
                }
            }
        }
        Method::Auto => {
            for coarse_sigma in [6, 8, 10, 12, 16] {
                for fine_sigma in [6, 8, 12, 16] {
                    base.push(Params::Auto(Auto {
                        coarse_sigma,
                        fine_sigma,
                        ..Auto::default()
                    }));
                }
            }
        }
        Method::Dog => {
            for sigma0_px in [2.0, 4.0, 8.0] {
                for levels in [3, 5, 7] {
                    for min_response_dn in [64, 128, 256, 512, 1024, 2048] {
                        base.push(Params::Dog(Dog {
                            sigma0_px,
                            sigma_ratio: 1.6,
                            levels,
                            min_response_dn,
                            ..Dog::default()
                        }));
                    }
                }
            }
        }
        // Otsu (the box rule is its only coordinate) and any detector without a grid
        // here: its defaults.
        _ => base.push(method.default_params()),
    }
    base.retain(is_valid);
    let mut out = Vec::with_capacity(2 * base.len() + 2);
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        for p in &base {
            let mut q = *p;
            q.set_box_rule(rule);
            if !out.contains(&q) {
                out.push(q);
            }
        }
    }
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        let d = defaults(method, rule);
        if !out.contains(&d) {
            out.push(d);
        }
    }
    out
}
