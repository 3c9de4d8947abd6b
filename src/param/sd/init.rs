//! The certified initial map of [`super::SymmetricDirichlet`] (Sec. 3.3). The circle
//! boundary of the Tutte map squeezes triangles of curved patches to ~1e-7 of their area,
//! and the optimisation from there needs many more iterations and can end in a worse local
//! minimum with the boundary pressed against itself; the free-boundary LSCM has no such
//! squeeze but is not bijective by construction. Hence: the LSCM if certified, else the
//! LSCM after the overlap repair if certified, else the Tutte map.

use super::super::lscm::lscm_on;
use super::super::sparse::VertexSystem;
use super::super::tutte::{certified_tutte, scale_to_area};
use super::newton::{newton, Mode};
use super::{SdOptions, SdProfile};
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use crate::param::{certify, ParamError};
use nalgebra::Point2;
use std::cell::OnceCell;
use std::time::Instant;

/// Which initial map [`initial_map`] chose.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum InitialMap {
    /// The free-boundary LSCM passed the certificate.
    Lscm,
    /// The overlapping LSCM after the overlap repair (`repair_iters`: locally injective
    /// symmetric Dirichlet steps with a penetration penalty) passed the certificate.
    RepairedLscm,
    /// Tutte map onto a circle (the certified fallback).
    CircleTutte,
}

/// The certified initial map of [`super::SymmetricDirichlet`], scaled to the 3D area: the
/// LSCM ([`crate::param::lscm()`]) if it passes the exact certificate
/// (`free_boundary_init`); else (`repair_iters > 0`) the repaired LSCM if it passes; else
/// the circle Tutte map (`init_weights`, then uniform).
pub fn initial_map(
    disk: &TriMesh,
    boundary: &[VertexId],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, InitialMap), ParamError> {
    initial_map_with(
        disk,
        boundary,
        options,
        &OnceCell::new(),
        &mut SdProfile::default(),
    )
}

fn ms_since(c: Instant) -> f64 {
    c.elapsed().as_secs_f64() * 1e3
}

/// [`initial_map`] with the linear system shared with the optimisation that follows; fills
/// the start-up part of `prof`.
pub(super) fn initial_map_with(
    disk: &TriMesh,
    boundary: &[VertexId],
    options: &SdOptions,
    system: &OnceCell<VertexSystem>,
    prof: &mut SdProfile,
) -> Result<(Vec<Point2<f64>>, InitialMap), ParamError> {
    let clock = Instant::now();
    if options.free_boundary_init {
        let lscm = VertexSystem::get(system, disk)
            .map_err(|failure| ParamError::Solver {
                system: crate::param::LinearSystem::VertexPattern,
                failure,
            })
            .and_then(|s| lscm_on(disk, boundary, s));
        if let Ok(mut uv) = lscm {
            scale_to_area(disk, &mut uv);
            let lscm_ok = certify(disk, &uv, boundary).is_ok();
            prof.lscm_ms = ms_since(clock);
            if lscm_ok {
                return Ok((uv, InitialMap::Lscm));
            }
            if options.repair_iters > 0 {
                if let Some(r) = repaired(disk, boundary, &uv, options, system, prof) {
                    return Ok((r, InitialMap::RepairedLscm));
                }
            }
        }
    }
    Ok((
        certified_tutte(disk, boundary, options.init_weights)?.0,
        InitialMap::CircleTutte,
    ))
}

/// The overlap repair of the uncertified LSCM `uv` (up to `repair_iters` locally injective
/// steps), scaled to the 3D area, if it passes the certificate.
fn repaired(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv: &[Point2<f64>],
    options: &SdOptions,
    system: &OnceCell<VertexSystem>,
    prof: &mut SdProfile,
) -> Option<Vec<Point2<f64>>> {
    let clock = Instant::now();
    let o = SdOptions {
        max_iters: options.repair_iters,
        ..*options
    };
    let mut out = None;
    if let Ok((mut r, log)) = newton(disk, boundary, uv, &o, Mode::LocallyInjective, system) {
        prof.repair = Some(log);
        scale_to_area(disk, &mut r);
        if certify(disk, &r, boundary).is_ok() {
            out = Some(r);
        }
    }
    prof.repair_ms = ms_since(clock);
    out
}
