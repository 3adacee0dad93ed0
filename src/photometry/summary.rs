//! A luminaire file's account, as a lighting designer checks one before placing it (`radiosity
//! info LAMP.ies`): what the file is, the web it gives, and the flux that web carries against
//! the lamps' rated flux (the light output ratio), the peak intensity and its direction, the
//! luminous opening and the efficacy.

use super::{IesVersion, OpeningShape, PhotometricType, Photometry, Source, Symmetry};
use serde::Serialize;
use std::fmt;
use std::path::Path;

/// Whether `path` names a photometric file by its extension (`.ies`, `.ldt`, any case).
pub fn is_photometric_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ies") || e.eq_ignore_ascii_case("ldt"))
}

/// One axis of the web: how many angles and their range, degrees.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Angles {
    pub count: usize,
    pub first: f64,
    pub last: f64,
}

impl Angles {
    fn of(a: &[f64]) -> Angles {
        Angles {
            count: a.len(),
            first: a.first().copied().unwrap_or(0.0),
            last: a.last().copied().unwrap_or(0.0),
        }
    }
}

/// What `radiosity info` prints of a luminaire file (and `--json` writes).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub file: String,
    /// "IES LM-63-2002", "EULUMDAT", …
    pub format: String,
    /// "C", "B" or "A".
    pub photometric_type: &'static str,
    pub symmetry: &'static str,
    /// Vertical and horizontal angles of the web as the file gives them.
    pub vertical: Angles,
    pub horizontal: Angles,
    pub lamps: u32,
    /// Rated flux of each lamp, lm; `None` for absolute photometry.
    pub lumens_per_lamp: Option<f64>,
    /// The flux the web carries, lm (its intensities integrated over the sphere).
    pub luminaire_lumens: f64,
    /// The luminaire's flux over its lamps' rated flux (relative photometry only).
    pub light_output_ratio: Option<f64>,
    /// The largest intensity in the web, cd, and where: (horizontal, vertical) angle, degrees.
    pub max_candela: f64,
    pub max_at: [f64; 2],
    pub input_watts: Option<f64>,
    /// Luminaire lumens per input watt.
    pub efficacy_lm_per_w: Option<f64>,
    pub opening_shape: &'static str,
    /// Width, length, height of the luminous opening, metres.
    pub opening_m: [f64; 3],
    /// The manufacturer's, catalogue's, luminaire's and lamp's names, where the file gives them.
    pub names: Vec<(String, String)>,
}

/// The account of `p`, read from `file`.
pub fn summarize(p: &Photometry, file: &str) -> Summary {
    let format = match &p.source {
        Source::Ies(i) => format!(
            "IES {}",
            match i.version {
                IesVersion::Lm63_1986 => "LM-63-1986",
                IesVersion::Lm63_1991 => "LM-63-1991",
                IesVersion::Lm63_1995 => "LM-63-1995",
                IesVersion::Lm63_2002 => "LM-63-2002",
                IesVersion::Lm63_2019 => "LM-63-2019",
            }
        ),
        Source::Eulumdat(_) => "EULUMDAT".to_string(),
    };
    let mut max = (0.0f64, [0.0; 2]);
    for (h, row) in p.horizontal.iter().zip(&p.candela) {
        for (v, &cd) in p.vertical.iter().zip(row) {
            if cd > max.0 {
                max = (cd, [*h, *v]);
            }
        }
    }
    let lumens = p.total_lumens();
    let lamp_lumens = p.lumens_per_lamp.map(|l| l * p.lamps.max(1) as f64);
    let o = &p.luminous_opening;
    let names = ["MANUFAC", "LUMCAT", "LUMINAIRE", "LAMP"];
    Summary {
        file: file.to_string(),
        format,
        photometric_type: match p.kind {
            PhotometricType::C => "C",
            PhotometricType::B => "B",
            PhotometricType::A => "A",
        },
        symmetry: symmetry_name(p.symmetry),
        vertical: Angles::of(&p.vertical),
        horizontal: Angles::of(&p.horizontal),
        lamps: p.lamps,
        lumens_per_lamp: p.lumens_per_lamp,
        luminaire_lumens: lumens,
        light_output_ratio: lamp_lumens.filter(|&l| l > 0.0).map(|l| lumens / l),
        max_candela: max.0,
        max_at: max.1,
        input_watts: p.input_watts,
        efficacy_lm_per_w: p.input_watts.filter(|&w| w > 0.0).map(|w| lumens / w),
        opening_shape: shape_name(o.shape),
        opening_m: [o.width, o.length, o.height],
        names: (p.keywords.iter())
            .filter(|(k, v)| names.contains(&k.as_str()) && !v.trim().is_empty())
            .cloned()
            .collect(),
    }
}

fn symmetry_name(s: Symmetry) -> &'static str {
    match s {
        Symmetry::Rotational => "rotational (one C-plane)",
        Symmetry::Quadrant => "quadrant (C0–C90)",
        Symmetry::BilateralC0 => "bilateral about C0–C180",
        Symmetry::BilateralC90 => "bilateral about C90–C270",
        Symmetry::Asymmetric => "none (every plane given)",
        Symmetry::Lateral => "lateral (0–90 mirrored)",
    }
}

fn shape_name(s: OpeningShape) -> &'static str {
    match s {
        OpeningShape::Point => "point",
        OpeningShape::Rectangle => "rectangle",
        OpeningShape::Box => "box with luminous sides",
        OpeningShape::Ellipse => "circle or ellipse",
        OpeningShape::VerticalCylinder => "vertical cylinder",
        OpeningShape::Ellipsoid => "sphere or ellipsoid",
        OpeningShape::HorizontalCylinderAlongLength => "horizontal cylinder along the length",
        OpeningShape::HorizontalCylinderAlongWidth => "horizontal cylinder along the width",
        OpeningShape::VerticalEllipseFacingLength => "vertical ellipse facing the 0° plane",
        OpeningShape::VerticalEllipseFacingWidth => "vertical ellipse facing the 90° plane",
        OpeningShape::Other => "other",
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let angles = |a: &Angles| format!("{} ({}° .. {}°)", a.count, a.first, a.last);
        writeln!(f, "luminaire      {}", self.file)?;
        writeln!(f, "format         {}", self.format)?;
        for (k, v) in &self.names {
            writeln!(f, "{:<15}{}", k.to_lowercase(), v.replace('\n', " "))?;
        }
        writeln!(
            f,
            "web            Type {}, symmetry {}; vertical angles {}, horizontal {}",
            self.photometric_type,
            self.symmetry,
            angles(&self.vertical),
            angles(&self.horizontal)
        )?;
        match self.lumens_per_lamp {
            Some(l) => writeln!(f, "lamps          {} × {:.0} lm", self.lamps, l)?,
            None => writeln!(f, "lamps          {} (absolute photometry)", self.lamps)?,
        }
        write!(f, "flux           {:.0} lm", self.luminaire_lumens)?;
        if let Some(r) = self.light_output_ratio {
            write!(f, " (light output ratio {:.1} %)", 100.0 * r)?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "peak           {:.0} cd at C {}°, γ {}°",
            self.max_candela, self.max_at[0], self.max_at[1]
        )?;
        if let Some(w) = self.input_watts {
            write!(f, "input          {w} W")?;
            if let Some(e) = self.efficacy_lm_per_w {
                write!(f, " ({e:.1} lm/W)")?;
            }
            writeln!(f)?;
        }
        let [w, l, h] = self.opening_m;
        writeln!(
            f,
            "opening        {} {w} × {l} × {h} m (width × length × height)",
            self.opening_shape
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An isotropic 1,000 cd lamp of 15,000 lm: the web carries 4π·1000 lm, so the light
    /// output ratio is 4π/15 and the peak is 1,000 cd; the names are listed.
    #[test]
    fn an_isotropic_lamp_is_summed_up() {
        let text = "IESNA:LM-63-2002\n[MANUFAC] ACME\n[LUMCAT] ISO-1\nTILT=NONE\n\
                    1 15000 1 3 1 1 2 0 0 0\n1 1 100\n0 90 180\n0\n1000 1000 1000\n";
        let p = super::super::parse_ies(text, "iso.ies").unwrap();
        let s = summarize(&p, "iso.ies");
        // The integration's own error is ~1e-5 (web.rs); 1e-3 leaves room for it.
        let exact = 4.0 * std::f64::consts::PI * 1000.0;
        assert!((s.luminaire_lumens / exact - 1.0).abs() < 1e-3, "{s:?}");
        let lor = s.light_output_ratio.unwrap();
        assert!((lor - exact / 15000.0).abs() < 1e-3, "{lor}");
        assert_eq!(s.max_candela, 1000.0);
        assert_eq!(s.format, "IES LM-63-2002");
        let text = s.to_string();
        assert!(
            text.contains("manufac        ACME") && text.contains("100 W"),
            "{text}"
        );
        assert!(is_photometric_file(Path::new("a/B.LDT")));
        assert!(!is_photometric_file(Path::new("room.obj")));
    }
}
