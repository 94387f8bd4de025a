//! The borehole's crack as the pressure rises: for every broken bond the hole pressure
//! and the extent of the crack connected to the hole wall ([`porofrac_lsm::crack`]), the
//! initiation pressure (first broken bond) and the breakdown pressure.
//!
//! **Breakdown** is the hole pressure at which the crack connected to the wall first
//! reaches one hole radius beyond it: extent `r_c ≥ 2a` from the hole centre. The lining
//! is the set of disks seen from the hole centre (the rays of
//! [`porofrac_lsm::WallFaces::Rays`]) in the reference configuration, whatever loads the
//! wall (rays, wetted faces or fluid), so that every loading is measured alike.
//! With `[loading] crack_across_pores` the crack is traced through the faces of the bond
//! network (the pores) it opens, from the pore that holds the hole
//! ([`porofrac_lsm::CrackExtent::across_pores`]); the lining then plays no part in it.
//!
//! Output: `crack.csv` (`time [s],i,j,pressure [Pa],extent [m]`, one row per broken bond in the order
//! of `broken.csv`), the scene-wide probe `crack_extent` (m) and the `summary.json` keys
//! `initiation_pressure`, `breakdown_pressure`, `breakdown_extent` (`2a`, m) and
//! `crack_extent` (m, at the end).

use std::path::Path;

use porofrac_lsm::{CrackExtent, LatticeSolid, LsmError, PressureWall};

use crate::RunError;

/// Extent of the wall crack at breakdown, in hole radii from the hole centre.
pub const BREAKDOWN_REACH: f64 = 2.0;

/// Pressure and crack extent at every broken bond of a scene with a hole.
#[derive(Clone, Debug)]
pub struct CrackLog {
    extent: CrackExtent,
    threshold: f64,
    /// `time, i, j, pressure, extent` per broken bond processed.
    rows: Vec<(f64, usize, usize, f64, f64)>,
    initiation: Option<f64>,
    breakdown: Option<f64>,
    written: usize,
}

impl CrackLog {
    /// The log of the hole of `centre` and `radius` in the reference configuration of
    /// `solid`; `across_pores`: the crack is traced through the pores it opens
    /// ([`CrackExtent::across_pores`]).
    pub fn new(
        solid: &LatticeSolid,
        centre: [f64; 2],
        radius: f64,
        across_pores: bool,
    ) -> Result<Self, LsmError> {
        let d = solid.disks();
        let lining: Vec<usize> = PressureWall::new(d, centre, radius)?
            .members
            .iter()
            .map(|m| m.0 as usize)
            .collect();
        let mut extent = CrackExtent::new(d.len(), &lining, centre)?;
        if across_pores {
            extent = extent.across_pores(d, solid.bonds())?;
        }
        Ok(Self {
            extent,
            threshold: BREAKDOWN_REACH * radius,
            rows: Vec::new(),
            initiation: None,
            breakdown: None,
            written: 0,
        })
    }

    /// Take in the bonds `solid` broke since the last call, at hole pressure `p` (Pa).
    pub fn sync(&mut self, solid: &LatticeSolid, p: f64) -> Result<(), LsmError> {
        for b in &solid.broken()[self.rows.len()..] {
            let e = self.extent.add(b.i, b.j, [b.x, b.y])?;
            self.initiation.get_or_insert(p);
            if e >= self.threshold && self.breakdown.is_none() {
                self.breakdown = Some(p);
            }
            self.rows.push((b.time, b.i, b.j, p, e));
        }
        Ok(())
    }

    /// Set `loads` to the forces of the pressure `p` (Pa) in the broken bonds of the crack
    /// connected to the wall ([`CrackExtent::flood_loads`]); returns how many are
    /// flooded. Call after [`Self::sync`].
    pub fn flood(
        &mut self,
        solid: &LatticeSolid,
        p: f64,
        loads: &mut [[f64; 3]],
    ) -> Result<usize, LsmError> {
        loads.fill([0.0; 3]);
        self.extent
            .flood_loads(solid.disks(), solid.broken(), p, loads)
    }

    /// Save the rows and pressures (the crack's connectivity follows from the broken
    /// bonds, [`CrackLog::restore`]).
    pub fn save(&self, state: &mut crate::common::checkpoint::State) {
        state.put_f64(
            "crack/rows",
            self.rows
                .iter()
                .flat_map(|r| [r.0, r.3, r.4])
                .collect::<Vec<_>>(),
        );
        let opt = |v: Option<f64>| v.map_or(Vec::new(), |p| vec![p]);
        state.put_f64("crack/initiation", opt(self.initiation));
        state.put_f64("crack/breakdown", opt(self.breakdown));
    }

    /// Put back what [`CrackLog::save`] saved, into a log just built, with `solid`
    /// restored: the crack is rebuilt by taking in the same broken bonds in the same
    /// order; `crack.csv` is rewritten at the next [`CrackLog::write_csv`].
    pub fn restore(
        &mut self,
        state: &crate::common::checkpoint::State,
        solid: &LatticeSolid,
    ) -> Result<(), RunError> {
        let rows = state.f64s("crack/rows")?;
        let n = rows.len() / 3;
        let broken = solid.broken();
        if rows.len() != 3 * n || n > broken.len() {
            return Err(RunError::Checkpoint(format!(
                "the crack log has {n} rows, the solid {} broken bonds",
                broken.len()
            )));
        }
        self.rows.clear();
        for (k, b) in broken[..n].iter().enumerate() {
            self.extent
                .add(b.i, b.j, [b.x, b.y])
                .map_err(|e| RunError::Checkpoint(format!("crack log: {e}")))?;
            self.rows
                .push((rows[3 * k], b.i, b.j, rows[3 * k + 1], rows[3 * k + 2]));
        }
        let opt = |name: &str| -> Result<Option<f64>, RunError> {
            Ok(state.f64s(name)?.first().copied())
        };
        self.initiation = opt("crack/initiation")?;
        self.breakdown = opt("crack/breakdown")?;
        self.written = usize::MAX;
        Ok(())
    }

    /// Extent of the crack connected to the wall (m from the hole centre).
    pub fn extent(&self) -> f64 {
        self.extent.extent()
    }

    /// `summary.json` keys.
    pub fn summary(&self, m: &mut serde_json::Map<String, serde_json::Value>) {
        let opt = |v: Option<f64>| v.map_or(serde_json::Value::Null, |p| p.into());
        m.insert("initiation_pressure".into(), opt(self.initiation));
        m.insert("breakdown_pressure".into(), opt(self.breakdown));
        m.insert("breakdown_extent".into(), self.threshold.into());
        m.insert("crack_extent".into(), self.extent().into());
    }

    /// Write `crack.csv` if bonds broke since the last write (atomically).
    pub fn write_csv(&mut self, out: &Path) -> Result<(), RunError> {
        if self.rows.len() == self.written && self.written > 0 {
            return Ok(());
        }
        let mut text = String::from("time [s],i,j,pressure [Pa],extent [m]\n");
        for (t, i, j, p, e) in &self.rows {
            text.push_str(&format!("{t:e},{i},{j},{p:e},{e:e}\n"));
        }
        crate::common::output::write_atomic(&out.join("crack.csv"), text.as_bytes())?;
        self.written = self.rows.len();
        Ok(())
    }
}
