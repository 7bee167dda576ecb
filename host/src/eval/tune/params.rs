//! Parameter sets of each method ([`Params`]), the refinement ladders and the grids.

use tirroi_core::roi::adaptive::Adaptive;
use tirroi_core::roi::auto::Auto;
use tirroi_core::roi::dog::Dog;
use tirroi_core::roi::otsu::Otsu;
use tirroi_core::roi::wge::Wge;
use tirroi_core::{BoxRule, Detector, Method};

use crate::eval::bank::DetectorBank;

/// One detector's parameter set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Params {
    /// Otsu parameters.
    Otsu(Otsu),
    /// Adaptive-threshold parameters.
    Adaptive(Adaptive),
    /// WGE parameters.
    Wge(Wge),
    /// DoG parameters.
    Dog(Dog),
    /// `auto` parameters (it has no box rule: setting one does nothing).
    Auto(Auto),
}

/// The command-line name of a box rule.
pub fn box_rule_name(rule: BoxRule) -> &'static str {
    match rule {
        BoxRule::AllForeground => "all-foreground",
        BoxRule::LargestComponent => "largest-component",
    }
}

fn other_rule(rule: BoxRule) -> BoxRule {
    match rule {
        BoxRule::AllForeground => BoxRule::LargestComponent,
        BoxRule::LargestComponent => BoxRule::AllForeground,
    }
}

impl Params {
    /// The core's default parameters of `method` with box rule `rule`.
    pub fn defaults(method: Method, rule: BoxRule) -> Params {
        let mut p = match method {
            Method::Otsu => Params::Otsu(Otsu::default()),
            Method::Adaptive => Params::Adaptive(Adaptive::default()),
            Method::Wge => Params::Wge(Wge::default()),
            Method::Dog => Params::Dog(Dog::default()),
            Method::Auto => Params::Auto(Auto::default()),
        };
        p.set_box_rule(rule);
        p
    }

    /// The parameters of `method` in `bank`.
    pub fn from_bank(bank: &DetectorBank, method: Method) -> Params {
        match method {
            Method::Otsu => Params::Otsu(bank.otsu),
            Method::Adaptive => Params::Adaptive(bank.adaptive),
            Method::Wge => Params::Wge(bank.wge),
            Method::Dog => Params::Dog(bank.dog),
            Method::Auto => Params::Auto(bank.auto),
        }
    }

    /// The detector these parameters belong to.
    pub fn method(&self) -> Method {
        match self {
            Params::Otsu(_) => Method::Otsu,
            Params::Adaptive(_) => Method::Adaptive,
            Params::Wge(_) => Method::Wge,
            Params::Dog(_) => Method::Dog,
            Params::Auto(_) => Method::Auto,
        }
    }

    /// The mask-to-box rule.
    pub fn box_rule(&self) -> BoxRule {
        match self {
            Params::Otsu(p) => p.box_rule,
            Params::Adaptive(p) => p.box_rule,
            Params::Wge(p) => p.box_rule,
            Params::Dog(p) => p.box_rule,
            Params::Auto(p) => p.box_rule(),
        }
    }

    /// Sets the mask-to-box rule.
    pub fn set_box_rule(&mut self, rule: BoxRule) {
        match self {
            Params::Otsu(p) => p.box_rule = rule,
            Params::Adaptive(p) => p.box_rule = rule,
            Params::Wge(p) => p.box_rule = rule,
            Params::Dog(p) => p.box_rule = rule,
            Params::Auto(_) => {}
        }
    }

    /// Whether the core accepts these parameters.
    pub fn is_valid(&self) -> bool {
        match self {
            Params::Otsu(p) => p.validate().is_ok(),
            Params::Adaptive(p) => p.validate().is_ok(),
            Params::Wge(p) => p.validate().is_ok(),
            Params::Dog(p) => p.validate().is_ok(),
            Params::Auto(p) => p.validate().is_ok(),
        }
    }

    /// Puts these parameters into `bank` (the other detectors are left as they are).
    pub fn apply(&self, bank: &mut DetectorBank) {
        match *self {
            Params::Otsu(p) => bank.otsu = p,
            Params::Adaptive(p) => bank.adaptive = p,
            Params::Wge(p) => bank.wge = p,
            Params::Dog(p) => bank.dog = p,
            Params::Auto(p) => bank.auto = p,
        }
    }

    /// `name=value` pairs separated by spaces, the box rule last, e.g.
    /// `block=41 offset_dn=64 box=largest-component` (no commas: a CSV field as is).
    pub fn describe(&self) -> String {
        let rule = box_rule_name(self.box_rule());
        match self {
            Params::Otsu(_) => format!("box={rule}"),
            Params::Adaptive(p) => {
                format!("block={} offset_dn={} box={rule}", p.block, p.offset_dn)
            }
            Params::Wge(p) => format!(
                "drop_fraction={} min_gradient={} box={rule}",
                p.drop_fraction, p.min_gradient
            ),
            Params::Dog(p) => format!(
                "sigma0_px={} sigma_ratio={} levels={} min_response_dn={} box={rule}",
                p.sigma0_px, p.sigma_ratio, p.levels, p.min_response_dn
            ),
            Params::Auto(p) => format!(
                "coarse_sigma={} fine_sigma={} margin_px={}",
                p.coarse_sigma, p.fine_sigma, p.margin_px
            ),
        }
    }

    /// The refinement neighbours: one ladder step down and up of each coordinate, and
    /// the other box rule; only valid sets.
    pub fn neighbours(&self) -> Vec<Params> {
        let mut out = Vec::new();
        let mut flipped = *self;
        flipped.set_box_rule(other_rule(self.box_rule()));
        if flipped != *self {
            out.push(flipped);
        }
        match *self {
            Params::Otsu(_) => {}
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
        }
        out.retain(Params::is_valid);
        out
    }
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
        Method::Otsu => base.push(Params::Otsu(Otsu::default())),
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
    }
    base.retain(Params::is_valid);
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
        let d = Params::defaults(method, rule);
        if !out.contains(&d) {
            out.push(d);
        }
    }
    out
}
