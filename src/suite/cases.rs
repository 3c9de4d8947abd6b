//! The catalogue of the analytic suite: one row per case (documented in the module doc of
//! [`crate::suite`], whose table the tests keep in step with this one).

use super::{Along, Case, Curve, Shape, Sizing};
use crate::mesh::generators::Hole;
use std::f64::consts::FRAC_PI_4;

const PLATE: Shape = Shape::Plate { cells: 40 };
/// The plate at 100×100 cells (0.01 apart), for the boundary layer and the shocks: their
/// sizes change fast across the wall or front, and the input's vertices must sample that
/// change finely enough for the interpolated `.sol` to still be the documented field.
const FINE_PLATE: Shape = Shape::Plate { cells: 100 };
const CYLINDER: Shape = Shape::Cylinder {
    radius: 1.0,
    height: 2.0,
    around: 128,
    along: 64,
};
const SPHERE: Shape = Shape::Sphere {
    radius: 1.0,
    subdivisions: 5,
};
const TORUS: Shape = Shape::Torus {
    major: 1.0,
    minor: 0.35,
    around: 160,
    tube: 56,
};
/// Three holes of radius 0.1, centred 0.55 from the origin at 90°, 210° and 330°: their walls
/// are 0.75 apart, so a boundary layer reaching its far size within 0.31 of a wall is
/// isotropic where the nearest hole changes (0.38 from each).
const HOLES: &[Hole] = &[
    Hole {
        centre: [0.0, 0.55],
        radius: 0.1,
    },
    Hole {
        centre: [-0.476_313_972_081_441_1, -0.275],
        radius: 0.1,
    },
    Hole {
        centre: [0.476_313_972_081_441_1, -0.275],
        radius: 0.1,
    },
];
const DISK_WITH_HOLES: Shape = Shape::DiskWithHoles {
    radius: 1.0,
    holes: HOLES,
    spacing: 0.025,
    wall_layers: &[0.004, 0.009, 0.015, 0.022],
};

const Z: [f64; 3] = [0.0, 0.0, 1.0];
const ORIGIN: [f64; 3] = [0.0, 0.0, 0.0];
/// Circles around the z axis: the cylinder's circumference, the sphere's parallels, the
/// torus's ring.
const AROUND_Z: Along = Along::AroundAxis {
    centre: ORIGIN,
    axis: Z,
    tilt: 0.0,
};

/// Constant anisotropy on the plate: fine across y, coarse along x.
const fn plate_aniso(h_across: f64, h_along: f64) -> Sizing {
    Sizing::Aligned {
        along: Along::Fixed([1.0, 0.0, 0.0]),
        h_across,
        h_along,
        core: 0.0,
    }
}

const fn case(name: &'static str, shape: Shape, sizing: Sizing) -> Case {
    Case {
        name,
        shape,
        sizing,
    }
}

/// The shock of the two plate cases.
const fn plate_shock(front: Curve) -> Sizing {
    Sizing::Shock {
        front,
        h_fine: 0.002,
        h_coarse: 0.04,
        width: 0.08,
    }
}

/// The analytic suite, in the order of its table.
pub const ANALYTIC: &[Case] = &[
    case("plate-iso", PLATE, Sizing::Isotropic { h: 0.02 }),
    case("plate-aniso10", PLATE, plate_aniso(0.006, 0.06)),
    case("plate-aniso30", PLATE, plate_aniso(0.004, 0.12)),
    case("plate-aniso100", PLATE, plate_aniso(0.002, 0.2)),
    case("plate-aniso1000", PLATE, plate_aniso(0.0005, 0.5)),
    case(
        "plate-turning10",
        PLATE,
        Sizing::Aligned {
            along: Along::AroundAxis {
                centre: [0.5, 0.5, 0.0],
                axis: Z,
                tilt: 0.0,
            },
            h_across: 0.006,
            h_along: 0.06,
            core: 0.15,
        },
    ),
    case(
        "plate-blayer",
        FINE_PLATE,
        Sizing::BoundaryLayer {
            wall: Curve::Plane {
                point: ORIGIN,
                normal: [0.0, 1.0, 0.0],
            },
            h0: 0.001,
            growth: 0.05,
            h_far: 0.04,
        },
    ),
    case(
        "plate-shock-sine",
        FINE_PLATE,
        plate_shock(Curve::Sine {
            y0: 0.5,
            amplitude: 0.15,
            wavelength: 1.0,
        }),
    ),
    case(
        "plate-shock-circle",
        FINE_PLATE,
        plate_shock(Curve::Circles(&[Hole {
            centre: [0.5, 0.5],
            radius: 0.3,
        }])),
    ),
    case("cylinder-iso", CYLINDER, Sizing::Isotropic { h: 0.1 }),
    case(
        "cylinder-axial10",
        CYLINDER,
        Sizing::Aligned {
            along: AROUND_Z,
            h_across: 0.03,
            h_along: 0.3,
            core: 0.0,
        },
    ),
    case(
        "cylinder-axial30",
        CYLINDER,
        Sizing::Aligned {
            along: AROUND_Z,
            h_across: 0.02,
            h_along: 0.6,
            core: 0.0,
        },
    ),
    case(
        "cylinder-helix10",
        CYLINDER,
        Sizing::Aligned {
            along: Along::AroundAxis {
                centre: ORIGIN,
                axis: Z,
                tilt: FRAC_PI_4,
            },
            h_across: 0.03,
            h_along: 0.3,
            core: 0.0,
        },
    ),
    case(
        "cylinder-blayer",
        CYLINDER,
        Sizing::BoundaryLayer {
            wall: Curve::Plane {
                point: ORIGIN,
                normal: Z,
            },
            h0: 0.005,
            growth: 0.1,
            h_far: 0.1,
        },
    ),
    case("sphere-iso", SPHERE, Sizing::Isotropic { h: 0.08 }),
    case(
        "sphere-turning10",
        SPHERE,
        Sizing::Aligned {
            along: AROUND_Z,
            h_across: 0.02,
            h_along: 0.2,
            core: 0.3,
        },
    ),
    case(
        "sphere-shock",
        SPHERE,
        Sizing::Shock {
            front: Curve::Plane {
                point: ORIGIN,
                normal: Z,
            },
            h_fine: 0.005,
            h_coarse: 0.08,
            width: 0.2,
        },
    ),
    case("torus-iso", TORUS, Sizing::Isotropic { h: 0.08 }),
    case(
        "torus-turning10",
        TORUS,
        Sizing::Aligned {
            along: AROUND_Z,
            h_across: 0.03,
            h_along: 0.3,
            core: 0.0,
        },
    ),
    case("holes-iso", DISK_WITH_HOLES, Sizing::Isotropic { h: 0.04 }),
    case(
        "holes-blayer",
        DISK_WITH_HOLES,
        Sizing::BoundaryLayer {
            wall: Curve::Circles(HOLES),
            h0: 0.003,
            growth: 0.15,
            h_far: 0.05,
        },
    ),
];
