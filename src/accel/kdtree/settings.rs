//! The kd-tree's parameters (`[accel.kdtree]`): how planes are chosen (the paper's spatial
//! median, or the surface area heuristic of Wald & Havran 2006), how deep and how full the tree
//! may grow, and the SAH's cost constants.

use super::MAX_DEPTH;
use serde::{Deserialize, Serialize};

/// How an inner node's plane is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    /// The middle of the node's longest side: the visibility-field paper's CRT baseline (Section
    /// 7), which its authors name as far from optimal.
    #[default]
    Median,
    /// The plane of least expected cost under the surface area heuristic, among the faces of
    /// every triangle clipped to the node ("perfect splits"), found by one sorted sweep per axis:
    /// Wald & Havran 2006 (the O(N log^2 N) sort-per-node form).
    Sah,
}

impl Split {
    /// Name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Split::Median => "median",
            Split::Sah => "sah",
        }
    }
}

/// The kd-tree's tuning knobs (`[accel.kdtree]`): the paper tuned its CRT on maximum depth and
/// leaf size; the SAH adds Wald & Havran's cost constants, absent under the median (which ignores
/// them) and their values where a SAH table leaves them out ([`KdSettings::costs`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KdSettings {
    /// How planes are chosen.
    pub split: Split,
    /// Deepest split level (the paper's best CRT depths: 16-23 for AO, 23 for the walkthrough).
    pub max_depth: u32,
    /// Nodes with at most this many triangles become leaves.
    pub leaf_size: u32,
    /// SAH: cost of one traversal step, K_T (Wald & Havran 2006; their value 15).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub traversal_cost: Option<f64>,
    /// SAH: cost of one triangle test, K_I (their value 20). Only the ratio K_T / K_I shapes the
    /// tree.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intersection_cost: Option<f64>,
    /// SAH: factor on the cost of a plane that leaves one side empty, lambda (their 0.8: cutting
    /// off empty space is favoured); 1 switches the bonus off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub empty_factor: Option<f64>,
}

/// The SAH's cost model (Wald & Havran 2006, with their empty-space factor).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SahCosts {
    /// K_T.
    pub traversal: f64,
    /// K_I.
    pub intersection: f64,
    /// lambda.
    pub empty_factor: f64,
}

/// Wald & Havran's constants: K_T = 15, K_I = 20, lambda = 0.8.
pub const PAPER_COSTS: SahCosts = SahCosts {
    traversal: 15.0,
    intersection: 20.0,
    empty_factor: 0.8,
};

impl Default for KdSettings {
    /// The spatial median at the best of `cargo bench --bench vlf_compare -- --tune-kdtree`
    /// (depths 16-30, leaves 2-32, AO rays along the 513 grid directions, one thread): depth 22
    /// and leaf 8 on the cow (1.56 Mrays/s) and bull (1.25); the man and the body peak deeper
    /// (26-28) within 10 %.
    fn default() -> Self {
        KdSettings {
            split: Split::Median,
            max_depth: 22,
            leaf_size: 8,
            traversal_cost: None,
            intersection_cost: None,
            empty_factor: None,
        }
    }
}

impl crate::accel::settings::Params for KdSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        if self.max_depth > MAX_DEPTH {
            return Err((
                "max_depth",
                format!("must lie in 0..={MAX_DEPTH} (the walk's stack), got {}", self.max_depth),
            ));
        }
        if self.leaf_size > 1 << 16 {
            return Err((
                "leaf_size",
                format!("must lie in 0..={}, got {}", 1 << 16, self.leaf_size),
            ));
        }
        let c = self.costs();
        for (key, v) in [("traversal_cost", c.traversal), ("intersection_cost", c.intersection)] {
            if !(v.is_finite() && v > 0.0 && v <= 1e6) {
                return Err((key, format!("must be a positive cost of at most 1e6, got {v}")));
            }
        }
        if !(c.empty_factor > 0.0 && c.empty_factor <= 1.0) {
            return Err(("empty_factor", format!("must lie in (0, 1], got {}", c.empty_factor)));
        }
        Ok(())
    }

    /// A median tree ignores the SAH's constants: they are dropped, so a grid crossing `split`
    /// with a cost list holds each median tree once; a SAH tree states all three.
    fn canonical(self) -> Self {
        let c = self.costs();
        let sah = self.split == Split::Sah;
        KdSettings {
            traversal_cost: sah.then_some(c.traversal),
            intersection_cost: sah.then_some(c.intersection),
            empty_factor: sah.then_some(c.empty_factor),
            ..self
        }
    }

    /// Both plane choices over the paper's CRT depths (16-23) and deeper to 30, at leaf sizes
    /// around the median's optimum (8), with traversal costs K_T from 1 to 60 around Wald &
    /// Havran's 15 (K_I = 20). `cargo bench --bench vlf_compare -- --tune-kdtree [--split sah]`
    /// times a wider grid on grid-direction AO rays: the median peaks at depths 22-28 and leaf 8,
    /// the SAH at depths 20-30 with leaf size and K_T in 1-15 within timing noise of each other
    /// (K_T 60 and depth 16 clearly slower; K_T 1, traversal nearly free, is the stated lower
    /// limit: below it the termination rule hardly stops a split and the depth limit decides).
    fn tuning() -> toml::Table {
        toml::toml! {
            split = ["median", "sah"]
            max_depth = [16, 18, 22, 26, 30]
            leaf_size = [2, 4, 8, 16]
            traversal_cost = [1.0, 5.0, 15.0, 60.0]
        }
    }
}

impl KdSettings {
    /// The SAH's constants: those given, Wald & Havran's for the rest.
    pub fn costs(&self) -> SahCosts {
        SahCosts {
            traversal: self.traversal_cost.unwrap_or(PAPER_COSTS.traversal),
            intersection: self.intersection_cost.unwrap_or(PAPER_COSTS.intersection),
            empty_factor: self.empty_factor.unwrap_or(PAPER_COSTS.empty_factor),
        }
    }

    /// The parameters in a few words: the median's as they always read, the SAH's with its
    /// constants.
    pub fn describe(&self) -> String {
        match self.split {
            Split::Median => format!("depth {} leaf {}", self.max_depth, self.leaf_size),
            Split::Sah => {
                let c = self.costs();
                format!(
                    "sah depth {} leaf {} K_T {} K_I {} lambda {}",
                    self.max_depth, self.leaf_size, c.traversal, c.intersection, c.empty_factor
                )
            }
        }
    }
}

/// `[accel.kdtree-sah]`: the kd-tree under the SAH by default, registered beside the median tree
/// so one experiment can time both side by side (the paper's open question, Section 9). `split`
/// may be left out or say `sah`.
pub fn sah_params(table: &toml::Table) -> Result<toml::Table, (String, String)> {
    let mut table = table.clone();
    match table.get("split").map(|v| v.as_str()) {
        None => {
            table.insert("split".into(), Split::Sah.name().into());
        }
        Some(Some("sah")) => {}
        Some(_) => {
            return Err((
                "split".into(),
                "`kdtree-sah` always splits by the SAH; the median tree is `kdtree`".into(),
            ))
        }
    }
    crate::accel::settings::validate::<KdSettings>(&table)
}

/// The SAH half of [`KdSettings`]' tuning grid.
pub fn sah_tuning() -> toml::Table {
    let mut grid = <KdSettings as crate::accel::settings::Params>::tuning();
    grid.insert("split".into(), toml::Value::Array(vec![Split::Sah.name().into()]));
    grid
}
