//! The two targets of the paper: the cube + cylinder of Section 4.1 (Table 3 material
//! cases) and a Tango-like satellite (PRISMA's Tango, Section 5); a generic small
//! satellite with two solar wings ([`winged_sat`], a shape the detectors were not
//! trained on); and a closed box for calibration and tests.
//!
//! # Cube + cylinder sizes and the 9-pixel rule
//!
//! The paper gives no sizes. We take a 1.0 m cube with a Ø 0.5 m × 1.0 m cylinder on
//! its +x face (axis along body +x), 2.0 m long overall. The far range (340–440 m) is
//! chosen in the paper so the target still covers at least 9 pixels; with the Hayabusa2
//! TIR camera (37 µm pixels, 42.2 mm focal length: IFOV 0.877 mrad) one pixel spans
//! 0.386 m at 440 m, i.e. 0.149 m². The target's projected area is 1.50 m² side-on
//! (10.1 px), about 1.9 m² on average over all attitudes (Cauchy: external area / 4 =
//! 7.57 / 4 m², 12.7 px; slightly less as the body is not convex) and 1.00 m² end-on
//! along x (6.7 px, the only attitudes below 9 px): the sizes meet the rule for all but
//! near end-on views at the far bound.
//!
//! # Tango sizes (all from public sources or marked as estimates)
//!
//! - Bus 0.74 × 0.57 × 0.295 m: the Tango envelope "570 × 740 × 295 mm" (40 kg) of
//!   the Prisma article of the German Wikipedia; the English Wikipedia gives
//!   "80 cm × 31 cm" (50 kg launch mass, 90 W), consistent with our overall 0.77 m
//!   width and 0.32 m height with the panel. CNES's FFIORD pages give 40 kg.
//! - One body-mounted solar panel on the +z face (Tango has "fixed solar panels",
//!   Spaceflight Now, 11 Aug 2010), 0.74 × 0.77 m, 25 mm thick, overhanging the bus
//!   by 0.10 m on ±y: *estimate*, after the Tango model of the SPEED dataset
//!   (Sharma and D'Amico's group, who also wrote the paper's reference \[4\]) as we
//!   recall its keypoints (panel corners near ±0.37 × ±0.385 m), not re-checked
//!   against the dataset files.
//! - Three whip antennas (inter-satellite link), Ø 10 mm, about 0.29 m long, in the
//!   plane 0.045 m below the panel: two from the +y wall at 45° outwards, one normal
//!   to the −y wall. Tips near (±0.54, 0.49) and (0.31, −0.58) m after the same
//!   recalled SPEED keypoints: *estimate*; diameter: *estimate*.
//! - Two patch antennas (GPS / formation-flying RF), 0.10 × 0.10 × 0.02 m, on the −z
//!   face: sizes and positions are *estimates* (Tango carried GPS and FFRF antennas,
//!   CNES FFIORD pages).
//!
//! # Tango materials (optical values after Gilmore, *Spacecraft Thermal Control
//! Handbook*, Vol. I, App. A, typical beginning-of-life values; assignment to
//! surfaces is an estimate)
//!
//! See [`SOLAR_CELLS`], [`PANEL_BACK`], [`WHITE_PAINT`], [`MLI_KAPTON`],
//! [`POLISHED_METAL`] and [`WHITE_RADOME`].

use serde::{Deserialize, Serialize};

use super::mesh::{CylinderSpec, Material, Mesh, MeshBuilder, Part, divisions};
use crate::world::geom::{Vec3, norm, sub};

/// Recommended facet edge length of both targets for close range (15–50 m, pixels of
/// 13–44 mm): 0.05 m, fine enough to carry the conduction gradients and to keep the
/// cylinder's polygon within 1.2 mm of the circle.
pub const DEFAULT_RESOLUTION_M: f64 = 0.05;

/// Recommended facet edge length at far range (340–440 m, pixels of 0.30–0.39 m):
/// 0.2 m, about half a pixel (508 facets for the cube + cylinder, 300 for Tango).
pub const FAR_RESOLUTION_M: f64 = 0.2;

/// Thermal conductivity of aluminium alloy 6061-T6, W m⁻¹ K⁻¹ (ASM handbook value).
pub const ALUMINIUM_CONDUCTIVITY_W_M_K: f64 = 167.0;

/// Density of aluminium alloy 6061, kg m⁻³ (ASM *Aerospace Specification Metals*
/// data sheet of 6061-T6: 2.70 g cm⁻³).
pub const ALUMINIUM_DENSITY_KG_M3: f64 = 2700.0;

/// Specific heat of aluminium alloy 6061 near room temperature, J kg⁻¹ K⁻¹ (ASM data
/// sheet of 6061-T6: 0.896 J g⁻¹ °C⁻¹; pure aluminium 0.897, CRC Handbook). It falls to
/// about 0.80 at 200 K and 0.68 at 150 K (CRC Handbook, aluminium): taking the room
/// temperature value overestimates the capacity of a cold (eclipse) skin by up to
/// ~25 %, so the computed eclipse cooling is slightly slow.
pub const ALUMINIUM_SPECIFIC_HEAT_J_KG_K: f64 = 896.0;

/// Areal heat capacity added by an aluminium honeycomb core, J m⁻² K⁻¹: a 15 mm core
/// (thickness an *estimate* for a 40 kg microsatellite's panels) of 5056 alloy
/// honeycomb, 3/16 in cells, 49.7 kg m⁻³ (3.1 lb ft⁻³, Hexcel HexWeb CR-III data
/// sheet): 0.75 kg m⁻² × 896 J kg⁻¹ K⁻¹.
pub const HONEYCOMB_CORE_J_M2_K: f64 = 0.015 * 49.7 * ALUMINIUM_SPECIFIC_HEAT_J_KG_K;

/// Conductance through a 25 mm aluminium honeycomb core from one face sheet to the other,
/// W m⁻² K⁻¹: the core's foils conduct as a solid of the core's density share of
/// aluminium, k ≈ 167 × 49.7 / 2700 ≈ 3.1 W m⁻¹ K⁻¹ (the core of
/// [`HONEYCOMB_CORE_J_M2_K`]; radiation inside the cells adds little at these
/// temperatures), over 25 mm: ≈ 123 (honeycomb panels' through-conductances are quoted at
/// 50–150, Gilmore, Vol. I, ch. 5). A sunlit wing's back then runs 4–5 K below its
/// cells instead of the ~60 K of two faces joined only along the panel's edges.
pub const HONEYCOMB_THROUGH_W_M2_K: f64 =
    ALUMINIUM_CONDUCTIVITY_W_M_K * (49.7 / ALUMINIUM_DENSITY_KG_M3) / 0.025;

/// Areal heat capacity added by the solar cells, J m⁻² K⁻¹: triple-junction GaAs/Ge
/// cells of about 0.86 kg m⁻² (Azur Space 3G30C data sheet: 86 mg cm⁻²) at
/// ~330 J kg⁻¹ K⁻¹ (germanium 320, GaAs 330, CRC Handbook) plus a 100 µm CMG cover
/// glass (2.55 g cm⁻³, 0.26 kg m⁻²) at ~700 J kg⁻¹ K⁻¹ (borosilicate glass) and
/// adhesive (neglected): 0.86·330 + 0.26·700 ≈ 466.
pub const SOLAR_CELL_LAYER_J_M2_K: f64 = 0.86 * 330.0 + 0.255 * 700.0;

/// Areal heat capacity added by an MLI blanket, J m⁻² K⁻¹: about 0.4 kg m⁻² for a
/// 15–20 layer blanket with its outer Kapton layer (Gilmore, *Spacecraft Thermal
/// Control Handbook*, Vol. I, ch. 5: blanket areal masses of 0.3–0.6 kg m⁻²) at
/// ~1 000 J kg⁻¹ K⁻¹ (Kapton: 1 090, DuPont data sheet; aluminised Mylar ~1 100).
/// Consistent with [`MLI_KAPTON`]'s simplification (blanket tied to the wall).
pub const MLI_BLANKET_J_M2_K: f64 = 0.4 * 1000.0;

/// Areal heat capacity of a surface of `material`, J m⁻² K⁻¹: its conducting aluminium
/// skin (every material of this module conducts through a 6061 sheet of
/// `thickness_m`: ρ c t = 2700 × 896 × t) plus the layers it carries, by material
/// name: the honeycomb core of Tango's sandwich panels ([`HONEYCOMB_CORE_J_M2_K`]:
/// `"solar-cells"`, `"black-paint"`, `"white-paint"`, `"mli-kapton"`), the cells of
/// `"solar-cells"` ([`SOLAR_CELL_LAYER_J_M2_K`]) and the blanket of `"mli-kapton"`
/// ([`MLI_BLANKET_J_M2_K`]). Paints (~0.1 kg m⁻²) are neglected.
///
/// Values: a 2 mm skin (cube + cylinder) 4 838; Tango's solar panel 3 549, white and
/// black walls 3 087, MLI walls 3 487, antennas (2.5 mm rod shell) 6 048, radomes 2 419.
pub fn areal_heat_capacity_j_m2_k(material: &Material) -> f64 {
    let skin =
        ALUMINIUM_DENSITY_KG_M3 * ALUMINIUM_SPECIFIC_HEAT_J_KG_K * material.thickness_m.max(0.0);
    let core = HONEYCOMB_CORE_J_M2_K;
    let added = match material.name {
        n if n == SOLAR_CELLS.name => core + SOLAR_CELL_LAYER_J_M2_K,
        n if n == PANEL_BACK.name || n == WHITE_PAINT.name => core,
        n if n == MLI_KAPTON.name => core + MLI_BLANKET_J_M2_K,
        _ => 0.0,
    };
    skin + added
}

/// Table 3 emissivity cases of the cube+cylinder target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialCase {
    /// Mono-material: ε_cube = 0.86, ε_cyl = 0.86.
    Mono,
    /// Multi-material 1: ε_cube = 0.90, ε_cyl = 0.10.
    #[serde(rename = "multi-1")]
    Multi1,
    /// Multi-material 2: ε_cube = 0.10, ε_cyl = 0.90.
    #[serde(rename = "multi-2")]
    Multi2,
}

impl MaterialCase {
    /// The three cases in Table 3 order.
    pub const ALL: [MaterialCase; 3] = [
        MaterialCase::Mono,
        MaterialCase::Multi1,
        MaterialCase::Multi2,
    ];

    /// Short name, as in scene files: `"mono"`, `"multi-1"`, `"multi-2"`.
    pub fn label(&self) -> &'static str {
        match self {
            MaterialCase::Mono => "mono",
            MaterialCase::Multi1 => "multi-1",
            MaterialCase::Multi2 => "multi-2",
        }
    }

    /// Table 3 emissivities `(ε_cube, ε_cyl)`.
    pub fn emissivities(&self) -> (f64, f64) {
        match self {
            MaterialCase::Mono => (0.86, 0.86),
            MaterialCase::Multi1 => (0.90, 0.10),
            MaterialCase::Multi2 => (0.10, 0.90),
        }
    }
}

impl std::str::FromStr for MaterialCase {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        MaterialCase::ALL
            .into_iter()
            .find(|c| c.label() == s)
            .ok_or_else(|| {
                format!("unknown material case {s:?}: expected mono, multi-1 or multi-2")
            })
    }
}

/// A grey Lambertian surface on a 2 mm aluminium skin (the cube + cylinder's parts).
///
/// The paper treats the target as a grey body ("diffused and gray", Section 4.1), so
/// the solar absorptivity equals the infrared emissivity: α = ε. The skin (conductivity
/// and thickness) is not given by the paper; 2 mm of 6061-T6 is our choice, which
/// leaves tens of kelvin between sunlit and shaded faces.
pub fn grey_aluminium_skin(name: &'static str, emissivity: f64) -> Material {
    Material {
        name,
        solar_absorptivity: emissivity,
        ir_emissivity: emissivity,
        conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
        thickness_m: 2e-3,
        core_conductance_w_m2_k: 0.0,
    }
}

/// Cube edge of [`cube_cylinder`], m.
pub const CUBE_EDGE_M: f64 = 1.0;
/// Cylinder diameter of [`cube_cylinder`], m.
pub const CYLINDER_DIAMETER_M: f64 = 0.5;
/// Cylinder length of [`cube_cylinder`] (from the cube face), m.
pub const CYLINDER_LENGTH_M: f64 = 1.0;

/// Segments around a circumference at a facet size: at least `min`, a multiple of 4 so
/// the polygon keeps the body's mirror symmetries.
fn segments(circumference_m: f64, resolution_m: f64, min: usize) -> usize {
    divisions(circumference_m, resolution_m, min).div_ceil(4) * 4
}

/// Facet size actually used: non-finite or non-positive values fall back to
/// [`DEFAULT_RESOLUTION_M`], and the size is kept within 2 mm ..= 10 m so facet counts
/// stay bounded (≈ 4.7 million facets for the cube + cylinder at 2 mm).
fn clamp_resolution(resolution_m: f64) -> f64 {
    if resolution_m.is_finite() && resolution_m > 0.0 {
        resolution_m.clamp(2e-3, 10.0)
    } else {
        DEFAULT_RESOLUTION_M
    }
}

/// The paper's simplified target (Section 4.1): a 1.0 m cube with a Ø 0.5 m × 1.0 m
/// cylinder attached to its +x face, axis along body +x (sizes and the 9-pixel check
/// in the [module docs](crate::world::spacecraft::models)).
///
/// Parts: 0 `"cube"`, 1 `"cylinder"`, grey ([`grey_aluminium_skin`]) with the Table 3
/// emissivities of `case`; no internal dissipation (the paper's target is passive).
/// Body frame: origin at the bounding-box centre, so the cube spans x ∈ [−1, 0] m, the
/// cylinder x ∈ [0, 1] m, and the joint plane is x = 0.
///
/// `resolution_m` is the facet edge length (see [`DEFAULT_RESOLUTION_M`]; clamped to
/// 2 mm ..= 10 m, invalid values give the default): each cube face is a grid of
/// ⌈1/res⌉² squares of two triangles, the cylinder side ⌈L/res⌉ rings × n segments
/// (n = ⌈π·D/res⌉ rounded up to a multiple of 4, at least 16), the free end cap ⌈r/res⌉
/// concentric rings. The attached end of the cylinder is open; the cube face under it
/// is kept (closed cube) and the thermal network finds those facets enclosed. At
/// 0.05 m: 4 800 + 1 280 + 288 = 6 368 facets.
pub fn cube_cylinder(case: MaterialCase, resolution_m: f64) -> Mesh {
    let res = clamp_resolution(resolution_m);
    let (eps_cube, eps_cyl) = case.emissivities();
    let mut b = MeshBuilder::new();
    let cube = b.part(Part {
        name: "cube",
        material: grey_aluminium_skin("grey-cube", eps_cube),
        dissipation_w: 0.0,
    });
    let cyl = b.part(Part {
        name: "cylinder",
        material: grey_aluminium_skin("grey-cylinder", eps_cyl),
        dissipation_w: 0.0,
    });
    let h = CUBE_EDGE_M / 2.0;
    b.box_faces([-h, -h, -h], [h, h, h], [Some(cube); 6], res);
    let r = CYLINDER_DIAMETER_M / 2.0;
    b.cylinder(
        cyl,
        CylinderSpec {
            base: [h, 0.0, 0.0],
            axis: [1.0, 0.0, 0.0],
            radius_m: r,
            length_m: CYLINDER_LENGTH_M,
            base_plane_normal: [1.0, 0.0, 0.0],
            segments: segments(std::f64::consts::PI * CYLINDER_DIAMETER_M, res, 16),
            rings: divisions(CYLINDER_LENGTH_M, res, 1),
            cap_rings: divisions(r, res, 1),
        },
    );
    b.finish()
}

/// Tango solar cells (top of the panel): α = 0.91, ε = 0.85, typical of triple-junction
/// GaAs cells with cover glass (Gilmore App. A: α 0.88–0.92, ε 0.80–0.85). The electrical
/// output (90 W peak, ~13 % of the absorbed power) is not removed: a slight
/// overestimate of the panel temperature. Substrate: aluminium honeycomb with two
/// 0.5 mm 6061 face sheets, k·t = 167 W m⁻¹ K⁻¹ × 1 mm (estimate).
pub const SOLAR_CELLS: Material = Material {
    name: "solar-cells",
    solar_absorptivity: 0.91,
    ir_emissivity: 0.85,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 1e-3,
    core_conductance_w_m2_k: 0.0,
};

/// Tango panel edges and overhanging underside: black paint (Aeroglaze Z306, Gilmore
/// App. A: α 0.95, ε 0.87) on the honeycomb substrate of [`SOLAR_CELLS`].
pub const PANEL_BACK: Material = Material {
    name: "black-paint",
    solar_absorptivity: 0.95,
    ir_emissivity: 0.87,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 1e-3,
    core_conductance_w_m2_k: 0.0,
};

/// Tango ±y walls: white-paint radiators (silicone white S13G/LO-1, Gilmore App. A:
/// α 0.20, ε 0.85) on 6061 honeycomb panels with two 0.5 mm face sheets (estimate).
pub const WHITE_PAINT: Material = Material {
    name: "white-paint",
    solar_absorptivity: 0.20,
    ir_emissivity: 0.85,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 1e-3,
    core_conductance_w_m2_k: 0.0,
};

/// Tango ±x walls and −z face: MLI blankets with an aluminised-Kapton outer layer,
/// Kapton side out (1 mil, Gilmore App. A: α 0.38, ε 0.67). Simplification: the
/// blanket's outer layer is tied to the wall panel below (6061 honeycomb, 1 mm of face
/// sheet); a real blanket runs hotter in sunlight and colder in shade.
pub const MLI_KAPTON: Material = Material {
    name: "mli-kapton",
    solar_absorptivity: 0.38,
    ir_emissivity: 0.67,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 1e-3,
    core_conductance_w_m2_k: 0.0,
};

/// Tango whip antennas: polished metal, α = 0.30, ε = 0.08 (between polished aluminium,
/// α 0.09–0.20 / ε 0.03–0.10, and polished stainless steel, α 0.42 / ε 0.11, Gilmore
/// App. A). Solid Ø 10 mm aluminium rod modelled as a shell of thickness r/2 = 2.5 mm
/// (same axial conductance k·π·r²).
pub const POLISHED_METAL: Material = Material {
    name: "polished-metal",
    solar_absorptivity: 0.30,
    ir_emissivity: 0.08,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 2.5e-3,
    core_conductance_w_m2_k: 0.0,
};

/// Tango patch antennas: white radome (white paint class, α = 0.25, ε = 0.85, estimate)
/// on a 1 mm aluminium box.
pub const WHITE_RADOME: Material = Material {
    name: "white-radome",
    solar_absorptivity: 0.25,
    ir_emissivity: 0.85,
    conductivity_w_m_k: ALUMINIUM_CONDUCTIVITY_W_M_K,
    thickness_m: 1e-3,
    core_conductance_w_m2_k: 0.0,
};

/// A bus's two parts, parts 0 and 1 of `b`: `"bus-radiator"` ([`WHITE_PAINT`], its
/// radiator walls of `radiator_area_m2`) and `"bus-mli"` ([`MLI_KAPTON`], the rest,
/// `mli_area_m2`), the internal `dissipation_w` split between them by area.
fn bus_parts(
    b: &mut MeshBuilder,
    dissipation_w: f64,
    radiator_area_m2: f64,
    mli_area_m2: f64,
) -> (u16, u16) {
    let share = dissipation_w / (radiator_area_m2 + mli_area_m2);
    let radiator = b.part(Part {
        name: "bus-radiator",
        material: WHITE_PAINT,
        dissipation_w: share * radiator_area_m2,
    });
    let mli = b.part(Part {
        name: "bus-mli",
        material: MLI_KAPTON,
        dissipation_w: share * mli_area_m2,
    });
    (radiator, mli)
}

/// Bus size of [`tango`] (x, y, z), m: 570 × 740 × 295 mm envelope.
pub const TANGO_BUS_M: Vec3 = [0.74, 0.57, 0.295];
/// Solar panel size of [`tango`] (x, y, thickness), m (estimate, see module docs).
pub const TANGO_PANEL_M: Vec3 = [0.74, 0.77, 0.025];
/// Internal dissipation of the Tango bus, W (estimate: the orbit-average electrical
/// load of a 40 kg microsatellite with a 90 W peak array), spread over the bus walls.
pub const TANGO_DISSIPATION_W: f64 = 10.0;

/// A Tango-like satellite (PRISMA's Tango, ref. \[14\] of the paper): box bus, one
/// body-mounted solar panel on +z, three whip antennas and two patch antennas.
/// Sizes, sources and estimates are listed in the [module docs](crate::world::spacecraft::models).
///
/// Parts: 0 `"bus-radiator"` ([`WHITE_PAINT`], ±y walls), 1 `"bus-mli"`
/// ([`MLI_KAPTON`], ±x walls and −z face), 2 `"solar-cells"` ([`SOLAR_CELLS`], panel
/// top), 3 `"panel-back"` ([`PANEL_BACK`], panel edges and underside overhang),
/// 4 `"whip-antennas"` ([`POLISHED_METAL`]), 5 `"patch-antennas"` ([`WHITE_RADOME`]).
/// [`TANGO_DISSIPATION_W`] is split between the two bus parts by area. Body frame:
/// x along the 0.74 m edge, z towards the panel; origin at the bounding-box centre.
/// The bus has no top face (the panel covers it); antennas are open at their base.
///
/// `resolution_m` as for [`cube_cylinder`] (whips: at least 8 segments).
pub fn tango(resolution_m: f64) -> Mesh {
    let res = clamp_resolution(resolution_m);
    let [bx, by, bz] = TANGO_BUS_M;
    let [px, py, pz] = TANGO_PANEL_M;
    let (hx, hy) = (bx / 2.0, by / 2.0);
    let (phx, phy) = (px / 2.0, py / 2.0);

    let mut b = MeshBuilder::new();
    let (radiator, mli) = bus_parts(
        &mut b,
        TANGO_DISSIPATION_W,
        2.0 * bx * bz,
        2.0 * by * bz + bx * by,
    );
    let cells = b.part(Part {
        name: "solar-cells",
        material: SOLAR_CELLS,
        dissipation_w: 0.0,
    });
    let back = b.part(Part {
        name: "panel-back",
        material: PANEL_BACK,
        dissipation_w: 0.0,
    });
    let whips = b.part(Part {
        name: "whip-antennas",
        material: POLISHED_METAL,
        dissipation_w: 0.0,
    });
    let patches = b.part(Part {
        name: "patch-antennas",
        material: WHITE_RADOME,
        dissipation_w: 0.0,
    });

    // Bus: z ∈ [0, bz], open top.
    b.box_faces(
        [-hx, -hy, 0.0],
        [hx, hy, bz],
        [
            Some(mli),
            Some(mli),
            Some(radiator),
            Some(radiator),
            Some(mli),
            None,
        ],
        res,
    );
    // Panel: z ∈ [bz, bz + pz]; the underside only where it overhangs the bus.
    b.box_faces(
        [-phx, -phy, bz],
        [phx, phy, bz + pz],
        [
            Some(back),
            Some(back),
            Some(back),
            Some(back),
            None,
            Some(cells),
        ],
        res,
    );
    let overhang = phy - hy;
    for y0 in [-phy, hy] {
        // u along +y, v along +x: u × v = −z (outward, down).
        b.grid(
            back,
            [-phx, y0, bz],
            [0.0, overhang, 0.0],
            [px, 0.0, 0.0],
            res,
        );
    }

    // Whip antennas, 0.045 m below the panel.
    let z = bz - 0.045;
    let whip_radius = 0.005;
    for (base, tip, wall_normal) in [
        ([-0.33, hy, z], [-0.54, 0.49, z], [0.0, 1.0, 0.0]),
        ([0.33, hy, z], [0.54, 0.49, z], [0.0, 1.0, 0.0]),
        ([0.305, -hy, z], [0.305, -0.58, z], [0.0, -1.0, 0.0]),
    ] {
        let axis = sub(tip, base);
        let length = norm(axis);
        b.cylinder(
            whips,
            CylinderSpec {
                base,
                axis,
                radius_m: whip_radius,
                length_m: length,
                base_plane_normal: wall_normal,
                segments: segments(std::f64::consts::TAU * whip_radius, res, 8),
                rings: divisions(length, res, 1),
                cap_rings: 1,
            },
        );
    }

    // Patch antennas on the −z face, open on top.
    let (side, depth) = (0.10, 0.02);
    for cx in [-0.2, 0.2] {
        b.box_faces(
            [cx - side / 2.0, -side / 2.0, -depth],
            [cx + side / 2.0, side / 2.0, 0.0],
            [
                Some(patches),
                Some(patches),
                Some(patches),
                Some(patches),
                Some(patches),
                None,
            ],
            res,
        );
    }
    b.finish()
}

/// Bus size of [`winged_sat`] (x, y, z), m: a generic small satellite of the 100–150 kg
/// class (*estimate*: the envelope of SSTL-100/150-type buses, 0.6 × 0.6 × 0.7 m).
pub const WINGED_BUS_M: Vec3 = [0.6, 0.6, 0.7];
/// Size of each of [`winged_sat`]'s two solar wings (thickness along x, length along y,
/// height along z), m (*estimate*: 0.6 m² of cells per wing, a 25 mm honeycomb panel as
/// Tango's).
pub const WINGED_WING_M: Vec3 = [0.025, 1.0, 0.6];
/// Gap between the bus's ±y wall and a wing's inner edge, bridged by the wing's yoke, m
/// (*estimate*).
pub const WINGED_YOKE_M: f64 = 0.15;
/// Yoke diameter, m (*estimate*: a Ø 30 mm tube, modelled as a closed-end rod).
pub const WINGED_YOKE_DIAMETER_M: f64 = 0.03;
/// The TT&C antenna on the bus's +z face: a white radome box (x, y, z), m (*estimate*).
pub const WINGED_ANTENNA_M: Vec3 = [0.12, 0.12, 0.08];
/// Internal dissipation of [`winged_sat`]'s bus, W (*estimate*: about the orbit average
/// of 1.2 m² of triple-junction cells, ~450 W at normal incidence, over a sunlit
/// fraction of 0.6 at an average cosine of 0.6, all of it ending as heat in the bus).
pub const WINGED_DISSIPATION_W: f64 = 150.0;

/// A generic small satellite with two deployed solar wings: the silhouette of most
/// inspection and servicing clients, and a shape none of `auto-v2`'s training sets
/// holds (the cube + cylinder and Tango are its training targets), so scores on it say
/// how the detector carries to a body it has never seen.
///
/// Box bus ([`WINGED_BUS_M`]), its ±x walls white-paint radiators ([`WHITE_PAINT`]),
/// the ±y walls and −z face MLI ([`MLI_KAPTON`]), the +z face MLI under a TT&C radome
/// ([`WINGED_ANTENNA_M`], [`WHITE_RADOME`]); two wings in the y–z plane, cells on
/// their +x face ([`SOLAR_CELLS`]), the −x face and edges black paint ([`PANEL_BACK`]),
/// the two faces joined through the panel's core ([`HONEYCOMB_THROUGH_W_M2_K`]),
/// each held [`WINGED_YOKE_M`] off the bus's ±y wall by a yoke ([`POLISHED_METAL`]).
/// The yokes are joined to the bus (their open base lies on its wall) and end in a cap
/// at the wing: the wings exchange heat by radiation only, as real arrays, thermally
/// decoupled from the bus at their hinges, nearly do.
///
/// Parts: 0 `"bus-radiator"`, 1 `"bus-mli"` ([`WINGED_DISSIPATION_W`] split between
/// the two by area), 2 `"solar-cells"`, 3 `"panel-back"`, 4 `"yokes"`, 5 `"antenna"`.
/// Body frame: wings along ±y, cells facing +x, the radome on +z; origin at the
/// bounding-box centre (2.9 × 0.6 × 0.78 m overall). `resolution_m` as for
/// [`cube_cylinder`] (yokes: at least 8 segments).
pub fn winged_sat(resolution_m: f64) -> Mesh {
    let res = clamp_resolution(resolution_m);
    let [bx, by, bz] = WINGED_BUS_M;
    let [wx, wy, wz] = WINGED_WING_M;
    let [ax, ay, az] = WINGED_ANTENNA_M;
    let (hx, hy) = (bx / 2.0, by / 2.0);
    // z: the bus and the radome on it, centred as a whole.
    let z0 = -(bz + az) / 2.0;
    let z_top = z0 + bz;
    let z_mid = z0 + bz / 2.0;

    let mut b = MeshBuilder::new();
    let (radiator, mli) = bus_parts(
        &mut b,
        WINGED_DISSIPATION_W,
        2.0 * by * bz,
        2.0 * bx * bz + 2.0 * bx * by,
    );
    // The wings' faces conduct through their honeycomb core (Tango's body-mounted panel
    // is modelled without it, as in the paper's case study).
    let cells = b.part(Part {
        name: "solar-cells",
        material: Material {
            core_conductance_w_m2_k: HONEYCOMB_THROUGH_W_M2_K,
            ..SOLAR_CELLS
        },
        dissipation_w: 0.0,
    });
    let back = b.part(Part {
        name: "panel-back",
        material: Material {
            core_conductance_w_m2_k: HONEYCOMB_THROUGH_W_M2_K,
            ..PANEL_BACK
        },
        dissipation_w: 0.0,
    });
    let yokes = b.part(Part {
        name: "yokes",
        material: POLISHED_METAL,
        dissipation_w: 0.0,
    });
    let antenna = b.part(Part {
        name: "antenna",
        material: WHITE_RADOME,
        dissipation_w: 0.0,
    });

    // Bus: closed (the radome sits on its +z face).
    b.box_faces(
        [-hx, -hy, z0],
        [hx, hy, z_top],
        [
            Some(radiator),
            Some(radiator),
            Some(mli),
            Some(mli),
            Some(mli),
            Some(mli),
        ],
        res,
    );
    // Radome, open at its base on the bus's +z face.
    b.box_faces(
        [-ax / 2.0, -ay / 2.0, z_top],
        [ax / 2.0, ay / 2.0, z_top + az],
        [
            Some(antenna),
            Some(antenna),
            Some(antenna),
            Some(antenna),
            None,
            Some(antenna),
        ],
        res,
    );
    let r = WINGED_YOKE_DIAMETER_M / 2.0;
    for side in [-1.0, 1.0] {
        // Wing: y from the yoke's end outwards, cells on +x.
        let (y_in, y_out) = (hy + WINGED_YOKE_M, hy + WINGED_YOKE_M + wy);
        let (ya, yb) = if side > 0.0 {
            (y_in, y_out)
        } else {
            (-y_out, -y_in)
        };
        b.box_faces(
            [-wx / 2.0, ya, z_mid - wz / 2.0],
            [wx / 2.0, yb, z_mid + wz / 2.0],
            [
                Some(back),
                Some(cells),
                Some(back),
                Some(back),
                Some(back),
                Some(back),
            ],
            res,
        );
        // Yoke: from the bus wall to the wing's inner edge, capped there.
        b.cylinder(
            yokes,
            CylinderSpec {
                base: [0.0, side * hy, z_mid],
                axis: [0.0, side, 0.0],
                radius_m: r,
                length_m: WINGED_YOKE_M,
                base_plane_normal: [0.0, side, 0.0],
                segments: segments(std::f64::consts::TAU * r, res, 8),
                rings: divisions(WINGED_YOKE_M, res, 1),
                cap_rings: 1,
            },
        );
    }
    b.finish()
}

/// A closed axis-aligned box of size `size_m` (x, y, z, m, each > 0) made of one part,
/// centred on the origin, at facet size `resolution_m` (as for [`cube_cylinder`]):
/// a calibration target for the thermal network (e.g. the isothermal check).
pub fn closed_box(size_m: Vec3, part: Part, resolution_m: f64) -> Mesh {
    let res = clamp_resolution(resolution_m);
    let mut b = MeshBuilder::new();
    let p = b.part(part);
    let h = size_m.map(|s| s.abs() / 2.0);
    b.box_faces([-h[0], -h[1], -h[2]], h, [Some(p); 6], res);
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_round_trip() {
        for c in MaterialCase::ALL {
            assert_eq!(c.label().parse::<MaterialCase>(), Ok(c));
        }
        assert!("multi3".parse::<MaterialCase>().is_err());
        for c in MaterialCase::ALL {
            let json = serde_json::to_string(&c).unwrap();
            assert_eq!(json, format!("\"{}\"", c.label()));
            assert_eq!(serde_json::from_str::<MaterialCase>(&json).unwrap(), c);
        }
    }

    /// The winged satellite's body frame: origin at the bounding-box centre, 2.9 × 0.6 ×
    /// 0.78 m overall (wings, bus, radome), and the ball of
    /// `TargetModel::WingedSat.inner_half_size_m()` inside the bus.
    #[test]
    fn winged_sat_is_centred_and_holds_its_inner_ball() {
        use crate::world::scene::TargetModel;
        let mesh = winged_sat(DEFAULT_RESOLUTION_M);
        let mut lo = [f64::MAX; 3];
        let mut hi = [f64::MIN; 3];
        for v in &mesh.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let span = WINGED_BUS_M[1] + 2.0 * (WINGED_YOKE_M + WINGED_WING_M[1]);
        let height = WINGED_BUS_M[2] + WINGED_ANTENNA_M[2];
        for (k, size) in [WINGED_BUS_M[0], span, height].into_iter().enumerate() {
            assert!((hi[k] + lo[k]).abs() < 1e-12, "axis {k}: {lo:?} .. {hi:?}");
            assert!(
                (hi[k] - lo[k] - size).abs() < 1e-12,
                "axis {k}: {lo:?} .. {hi:?}"
            );
        }
        // The bus's walls: ±x, ±y at half its size; −z at the bottom, +z under the radome.
        let bottom = -height / 2.0;
        let walls = [
            WINGED_BUS_M[0] / 2.0,
            WINGED_BUS_M[1] / 2.0,
            -bottom,
            bottom + WINGED_BUS_M[2],
        ];
        let inner = TargetModel::WingedSat.inner_half_size_m();
        assert!(walls.iter().all(|&d| d >= inner), "{walls:?} vs {inner}");
        assert_eq!(mesh.parts.len(), 6);
    }

    #[test]
    fn default_facet_counts() {
        assert_eq!(
            cube_cylinder(MaterialCase::Mono, DEFAULT_RESOLUTION_M).facet_count(),
            6368
        );
    }
}
