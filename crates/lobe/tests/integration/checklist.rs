//! The "add a model" checklist of docs/ARCHITECTURE.md, enforced: every
//! model of `lobe::models::MODELS` has a row here, and for every row the
//! pieces a model needs exist. A model without a row, or a row whose piece
//! is missing, fails with a message that names the missing piece and where
//! it goes.

use lobe::batch::BatchSampler;
use lobe::models::MODELS;
use lobe::{BsdfStrategy, Material};
use std::path::Path;

/// One model's pieces.
struct Row {
    /// The model's `type` name (`lobe::models::ModelInfo::name`).
    model: &'static str,
    /// Materials of the model that between them reach every strategy it
    /// has.
    examples: fn() -> Vec<Material>,
    /// The integration test that runs its samplers' chi-square tests.
    chi2_test: &'static str,
    /// How the README's model table names it (the start of its row).
    readme_row: &'static str,
    /// For a model under another's name (Mitsuba's `diffuse`,
    /// `roughconductor`; `twosided`), the model its materials are.
    alias_of: Option<&'static str>,
    /// Why its samplers have no batch kernel yet, as the batch module's doc
    /// says it (`None`: every strategy is batched).
    scalar_only: Option<&'static str>,
    /// With `scalar_only`, the strategies of its examples that are batched
    /// all the same (rough glass's GGX vndf).
    batched: &'static [BsdfStrategy],
}

fn load(json: &str) -> Material {
    Material::load(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

const ROWS: &[Row] = &[
    Row {
        model: "lambert",
        examples: || vec![load(r#"{"type":"lambert"}"#)],
        chi2_test: "fn chi2_lambert",
        readme_row: "| Lambert |",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "phong",
        examples: || vec![load(r#"{"type":"phong","exponent":20,"kd":0.3}"#)],
        chi2_test: "fn chi2_phong_and_blinn_phong",
        readme_row: "| Phong ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "blinn-phong",
        examples: || vec![load(r#"{"type":"blinn-phong","exponent":20}"#)],
        chi2_test: "fn chi2_phong_and_blinn_phong",
        readme_row: "| Blinn-Phong ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "cook-torrance",
        examples: || {
            vec![
                load(r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.3,"kd":0.2}"#),
                load(r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.3}"#),
                load(r#"{"type":"cook-torrance","distribution":"blinn-phong","alpha":0.3}"#),
            ]
        },
        chi2_test: "fn chi2_microfacet_ggx",
        readme_row: "| Cook-Torrance",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "measured",
        examples: || {
            vec![
                super::measured::ggx_merl().clone(),
                super::measured::beckmann_rgl().clone(),
            ]
        },
        chi2_test: "fn chi2_of_the_rgl_warps",
        readme_row: "| Measured",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "conductor",
        examples: || vec![load(r#"{"type":"conductor","material":"Au"}"#)],
        chi2_test: "fn smooth_conductor",
        readme_row: "| Smooth conductor ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "dielectric",
        examples: || vec![load(r#"{"type":"dielectric"}"#)],
        chi2_test: "fn delta_parts_directions_probabilities_and_weights",
        readme_row: "| Smooth dielectric ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "thindielectric",
        examples: || vec![load(r#"{"type":"thindielectric"}"#)],
        chi2_test: "fn delta_parts_directions_probabilities_and_weights",
        readme_row: "| Thin dielectric ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "roughdielectric",
        examples: || {
            vec![load(
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
            )]
        },
        chi2_test: "fn chi2_rough_dielectric",
        readme_row: "| Rough dielectric ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "plastic",
        examples: || vec![load(r#"{"type":"plastic"}"#)],
        chi2_test: "fn chi2_plastic_and_two_sided",
        readme_row: "| Smooth plastic ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "roughplastic",
        examples: || vec![load(r#"{"type":"roughplastic","distribution":"ggx"}"#)],
        chi2_test: "fn chi2_plastic_and_two_sided",
        readme_row: "| Rough plastic ",
        alias_of: None,
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "diffuse",
        examples: || vec![load(r#"{"type":"diffuse"}"#)],
        chi2_test: "fn mitsuba_names",
        readme_row: "| Mitsuba's names ",
        alias_of: Some("lambert"),
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "roughconductor",
        examples: || vec![load(r#"{"type":"roughconductor","distribution":"ggx"}"#)],
        chi2_test: "fn mitsuba_names",
        readme_row: "| Mitsuba's names ",
        alias_of: Some("cook-torrance"),
        scalar_only: None,
        batched: &[],
    },
    Row {
        model: "twosided",
        examples: || {
            vec![load(
                r#"{"type":"twosided","bsdf":{"type":"roughconductor","distribution":"ggx"}}"#,
            )]
        },
        chi2_test: "fn chi2_plastic_and_two_sided",
        readme_row: "| Two-sided ",
        alias_of: Some("cook-torrance"),
        scalar_only: None,
        batched: &[],
    },
];

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_model_has_its_row() {
    for m in MODELS {
        assert!(
            ROWS.iter().any(|r| r.model == m.name),
            "model {} has no row in crates/lobe/tests/integration/checklist.rs \
             (docs/ARCHITECTURE.md, \"Add a model\")",
            m.name
        );
    }
    for r in ROWS {
        assert!(
            MODELS.iter().any(|m| m.name == r.model),
            "checklist row {} names no model of lobe::models::MODELS",
            r.model
        );
        for m in (r.examples)() {
            assert_eq!(
                m.model_name(),
                r.alias_of.unwrap_or(r.model),
                "an example of {} is not one",
                r.model
            );
        }
    }
}

/// Every strategy of every model has a batch kernel (`lobe::batch`), or the
/// model's row says why not in the words of the batch module's doc (and the
/// batch path refuses it). Every model has `brdf`, and `uniform` and
/// `cosine` unless it has a delta part.
#[test]
fn every_strategy_of_every_model_is_batched() {
    let batch_doc = read("src/batch/mod.rs");
    for r in ROWS {
        let mut reached = Vec::new();
        if let Some(why) = r.scalar_only {
            assert!(
                batch_doc.contains(why),
                "model {}: the batch module's doc (crates/lobe/src/batch/mod.rs) does not say `{why}`",
                r.model
            );
        }
        for m in (r.examples)() {
            for s in m.strategies() {
                match (BatchSampler::new(&m, s), r.scalar_only) {
                    (Err(e), None) => panic!(
                        "model {} strategy {s} has no batch kernel ({e}): add it in \
                         crates/lobe/src/batch (kernel_for) or say in the batch module \
                         doc why it is scalar only",
                        r.model
                    ),
                    (Ok(_), Some(why)) if !r.batched.contains(&s) => panic!(
                        "model {} strategy {s} is batched: remove `{why}` from its row, or name the strategy in its `batched`",
                        r.model
                    ),
                    (Err(e), Some(_)) if r.batched.contains(&s) => panic!(
                        "model {} strategy {s} is in its row's `batched` but refused: {e}",
                        r.model
                    ),
                    _ => {}
                }
                reached.push(s);
            }
            let needed: &[BsdfStrategy] = if m.reach().delta {
                &[BsdfStrategy::Brdf]
            } else {
                &[
                    BsdfStrategy::Uniform,
                    BsdfStrategy::Cosine,
                    BsdfStrategy::Brdf,
                ]
            };
            assert!(
                needed.iter().all(|s| reached.contains(s)),
                "the examples of {} miss a strategy every such model has",
                r.model
            );
        }
    }
}

/// Every model has a chi-square test of its samplers, a row in the
/// README's model table and a name in the Python module's docs.
#[test]
fn every_model_is_tested_documented_and_named_in_python() {
    let tests = [
        "tests/integration/chi2.rs",
        "tests/integration/measured.rs",
        "tests/integration/glass.rs",
    ]
    .map(read)
    .join("\n");
    let readme = read("../../README.md");
    let stubs = read("../../python/lobe/_lobe.pyi");
    for r in ROWS {
        assert!(
            tests.contains(r.chi2_test),
            "model {}: no chi-square test `{}` in crates/lobe/tests/integration",
            r.model,
            r.chi2_test
        );
        assert!(
            readme.lines().any(|l| l.starts_with(r.readme_row)),
            "model {}: no row starting `{}` in the README's model table",
            r.model,
            r.readme_row
        );
        assert!(
            [" ", "("].iter().any(|a| [",", ")"]
                .iter()
                .any(|b| stubs.contains(&format!("{a}{}{b}", r.model)))),
            "model {}: not among the model names of python/lobe/_lobe.pyi (Material.model)",
            r.model
        );
    }
}
