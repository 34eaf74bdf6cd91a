//! Named refractive indices: the dielectrics that Mitsuba 3 accepts for
//! `int_ior` and `ext_ior` ([`IORS`]) and its named conductors with their
//! complex index in RGB ([`CONDUCTORS`]), looked up by name
//! ([`dielectric`], [`conductor`]).

use crate::Error;
use crate::math::Rgb;

/// The conductors Mitsuba 3 names in `material` and their complex
/// refractive index `(eta, k)` in RGB: the values Mitsuba's RGB variants
/// use (its spectral data integrated to sRGB, read from Mitsuba 3.9.1's
/// `scalar_rgb` plugin with `mi.traverse`; `bench/mitsuba_conductors.py`
/// prints them), to 6 digits. Mitsuba's `_palik` names are the same data.
#[rustfmt::skip]
#[allow(clippy::unreadable_literal, clippy::excessive_precision)]
pub const CONDUCTORS: [(&str, [f64; 3], [f64; 3]); 65] = [
    ("a-C", [2.94405, 2.22714, 1.96816], [0.887465, 0.799299, 0.81529]),
    ("Ag", [0.155276, 0.116728, 0.138388], [4.82835, 3.12222, 2.1469]),
    ("Al", [1.6575, 0.880405, 0.521244], [9.22381, 6.2695, 4.837]),
    ("AlAs", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("AlAs_palik", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("AlSb", [0.0, 4.13937, 4.66925], [0.0, 0.0940091, 1.30057]),
    ("AlSb_palik", [0.0, 4.13937, 4.66925], [0.0, 0.0940091, 1.30057]),
    ("Au", [0.143036, 0.375307, 1.44205], [3.983, 2.38556, 1.60336]),
    ("Be", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Be_palik", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Cr", [4.36967, 2.91651, 1.6549], [5.20655, 4.23131, 3.7547]),
    ("CsI", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("CsI_palik", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("Cu", [0.201005, 0.92375, 1.10222], [3.91326, 2.45305, 2.14209]),
    ("Cu_palik", [0.213229, 0.919715, 1.10241], [3.92187, 2.45733, 2.13658]),
    ("Cu2O", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("Cu2O_palik", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("CuO", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("CuO_palik", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("d-C", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("d-C_palik", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("Hg", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("Hg_palik", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("HgTe", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("HgTe_palik", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("Ir", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("Ir_palik", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("K", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("K_palik", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("Li", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("Li_palik", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("MgO", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("MgO_palik", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("Mo", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Mo_palik", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Na_palik", [0.0602694, 0.0561409, 0.0619884], [3.17927, 2.11249, 1.57904]),
    ("Nb", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Nb_palik", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Ni_palik", [2.3673, 1.66337, 1.46708], [4.49881, 3.05015, 2.34544]),
    ("Rh", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Rh_palik", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Se", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("Se_palik", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("SiC", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SiC_palik", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SnTe", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("SnTe_palik", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("Ta", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Ta_palik", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Te", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("Te_palik", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("ThF4", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("ThF4_palik", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("TiC", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiC_palik", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiN", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiN_palik", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiO2", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("TiO2_palik", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("VC", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("VC_palik", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("V_palik", [4.27758, 3.51295, 2.76107], [3.4913, 2.88945, 3.11152]),
    ("VN", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("VN_palik", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("W", [4.37082, 3.30025, 2.99841], [3.50064, 2.60487, 2.27323]),
];

/// Named refractive indices that Mitsuba accepts for `int_ior`/`ext_ior`:
/// the published values (Hecht, *Optics*, 4th ed.; near 589 nm, 0–20 °C).
pub const IORS: [(&str, f64); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// The index of refraction named `name` (any case), or an error that lists
/// the names; `field` names the key in the message.
pub fn dielectric(field: &str, name: &str) -> Result<f64, Error> {
    IORS.iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|&(_, x)| x)
        .ok_or_else(|| Error::UnknownName {
            field: field.into(),
            value: name.into(),
            expected: IORS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
        })
}

/// The RGB complex index `(eta, k)` of the conductor named `name` (exact
/// case, as Mitsuba writes it), or an error that lists the names; `field`
/// names the key in the message. `AlSb`, whose red `eta` is zero in
/// Mitsuba's RGB data (not a physical index), is refused with that reason.
pub fn conductor(field: &str, name: &str) -> Result<(Rgb, Rgb), Error> {
    let Some(&(_, eta, k)) = CONDUCTORS.iter().find(|(n, _, _)| *n == name) else {
        return Err(Error::UnknownName {
            field: field.into(),
            value: name.into(),
            expected: format!(
                "none, {}",
                CONDUCTORS
                    .iter()
                    .map(|(n, _, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        });
    };
    if eta.contains(&0.0) {
        return Err(Error::param(
            field,
            format!(
                "{name}: Mitsuba's RGB data gives it a zero eta channel ({eta:?}), not a physical index; give eta and k instead"
            ),
        ));
    }
    Ok((Rgb::from_array(eta), Rgb::from_array(k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_found_and_unknown_ones_listed() {
        assert_eq!(dielectric("int_ior", "BK7").unwrap(), 1.5046);
        assert_eq!(dielectric("ext_ior", "air").unwrap(), 1.000_277);
        let e = dielectric("int_ior", "glass").unwrap_err().to_string();
        assert!(
            e.contains("int_ior") && e.contains("glass") && e.contains("diamond"),
            "{e}"
        );
        let (eta, k) = conductor("material", "Au").unwrap();
        assert!(eta.x < eta.z && k.x > k.z, "gold: {eta} {k}");
        let e = conductor("material", "Gold").unwrap_err().to_string();
        assert!(e.contains("material") && e.contains("Cu"), "{e}");
        assert!(
            conductor("material", "AlSb")
                .unwrap_err()
                .to_string()
                .contains("zero eta")
        );
    }
}
