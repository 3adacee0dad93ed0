//! The building's materials and its MTL file.

use std::io::{self, Write};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Mat {
    Wall,
    Floor,
    CorridorFloor,
    Ceiling,
    Light,
    Glass,
    Wood,
    Fabric,
    Cabinet,
    Stair,
    Roof,
    AtticFloor,
}

impl Mat {
    pub(super) const ALL: [Mat; 12] = [
        Mat::Wall,
        Mat::Floor,
        Mat::CorridorFloor,
        Mat::Ceiling,
        Mat::Light,
        Mat::Glass,
        Mat::Wood,
        Mat::Fabric,
        Mat::Cabinet,
        Mat::Stair,
        Mat::Roof,
        Mat::AtticFloor,
    ];

    /// (name, comment, Kd, Ke).
    pub(super) fn spec(self) -> (&'static str, &'static str, [f32; 3], Option<[f32; 3]>) {
        match self {
            Mat::Wall => ("wall", "walls and reveals", [0.72, 0.7, 0.65], None),
            Mat::Floor => ("floor", "room floors", [0.35, 0.33, 0.3], None),
            Mat::CorridorFloor => ("corridor_floor", "", [0.45, 0.45, 0.42], None),
            Mat::Ceiling => ("ceiling", "", [0.8, 0.8, 0.8], None),
            Mat::Light => (
                "light",
                "ceiling panels and lanterns: E = pi * Ke = 31.4 W/m2",
                [0.8, 0.8, 0.8],
                Some([10.0, 10.0, 10.0]),
            ),
            Mat::Glass => (
                "glass",
                "window panes: low reflectance, no emission (night outside)",
                [0.04, 0.04, 0.05],
                None,
            ),
            Mat::Wood => ("wood", "desks and tables", [0.55, 0.38, 0.22], None),
            Mat::Fabric => ("fabric", "chairs and sofas", [0.25, 0.28, 0.4], None),
            Mat::Cabinet => (
                "cabinet",
                "shelves, cabinets, lantern bodies",
                [0.5, 0.5, 0.52],
                None,
            ),
            Mat::Stair => ("stair", "flights and slab edges", [0.6, 0.58, 0.55], None),
            Mat::Roof => ("roof", "underside of the roof", [0.5, 0.38, 0.25], None),
            Mat::AtticFloor => ("attic_floor", "", [0.45, 0.4, 0.35], None),
        }
    }
}

pub(super) fn write_mtl(mtl: &mut dyn Write) -> io::Result<()> {
    writeln!(
        mtl,
        "# Materials of a building written by `radiosity generate building`."
    )?;
    writeln!(
        mtl,
        "# Kd: diffuse reflectance; Ke: emitted radiance, W/sr/m²."
    )?;
    for m in Mat::ALL {
        let (name, comment, kd, ke) = m.spec();
        writeln!(mtl)?;
        if !comment.is_empty() {
            writeln!(mtl, "# {comment}")?;
        }
        writeln!(mtl, "newmtl {name}")?;
        writeln!(mtl, "Kd {} {} {}", kd[0], kd[1], kd[2])?;
        if let Some(ke) = ke {
            writeln!(mtl, "Ke {} {} {}", ke[0], ke[1], ke[2])?;
        }
    }
    Ok(())
}
