//! The settings of one estimate table (`lobe estimate`, Python's
//! `lobe.estimate`), checked in one place, and the table they ask for.
//! Each front end reads its own flags or keyword arguments into
//! [`EstimateTableSettings`] and names a [`SettingsError`]'s [`Setting`] in its
//! own spelling (`--mis-samples`, `mis_samples`).

use super::table::{Table, TableSettings, run_table};
use crate::estimator::ShadingPoint;
use crate::progress::{Clock, Progress};
use crate::sequence::Sequence;
use crate::{BsdfStrategy, Light, Material, Strategy};

/// Largest number of BSDF or light draws per MIS estimate.
pub const MAX_MIS_SAMPLES: u32 = 64;

/// The settings of one table, as given (names not yet parsed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EstimateTableSettings {
    /// `all` or strategy names ([`Strategy::parse_list`]).
    pub strategies: Vec<String>,
    /// The BSDF strategy MIS combines with light sampling; `None`: the
    /// material's best ([`Material::best_bsdf_strategy`]).
    pub mis_bsdf: Option<String>,
    /// BSDF and light draws per MIS estimate, each 1 to [`MAX_MIS_SAMPLES`].
    pub mis_samples: (u32, u32),
    /// Samples per strategy, at least 2.
    pub samples: usize,
    /// `independent`, `stratified` or `sobol`.
    pub sequence: String,
    pub seed: u64,
    /// Randomized replicas for the standard error under stratified and
    /// Sobol sequences (at least 2, at most `samples`).
    pub replicas: usize,
}

/// Which setting an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    Strategies,
    MisBsdf,
    MisSamples,
    Samples,
    Sequence,
    Replicas,
}

/// A setting that cannot be used, or a table that came out not finite:
/// `setting` (where the fault is a setting), what was given and why it
/// cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingsError {
    pub setting: Option<Setting>,
    /// The value as given (empty where it says nothing more).
    pub value: String,
    /// Why; where it names another setting, `{see}` stands for it
    /// ([`SettingsError::see`], filled in by [`SettingsError::named`]).
    pub message: String,
    /// The other setting the message names, with its value.
    pub see: Option<(Setting, String)>,
}

impl SettingsError {
    fn new(setting: Setting, value: impl ToString, message: impl Into<String>) -> Self {
        SettingsError {
            setting: Some(setting),
            value: value.to_string(),
            message: message.into(),
            see: None,
        }
    }

    /// The message with the setting named by `name` (a front end's
    /// spelling): `NAME VALUE: MESSAGE`, or `NAME: MESSAGE` without a value.
    #[must_use]
    pub fn named(&self, name: impl Fn(Setting) -> &'static str) -> String {
        let message = match &self.see {
            Some((s, v)) => self.message.replace("{see}", &format!("{} {v}", name(*s))),
            None => self.message.clone(),
        };
        match (self.setting, self.value.is_empty()) {
            (Some(s), true) => format!("{}: {message}", name(s)),
            (Some(s), false) => format!("{} {}: {message}", name(s), self.value),
            (None, _) => message,
        }
    }
}

/// The settings checked for `m`: the strategies to run and the table's
/// settings.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedSettings {
    pub strategies: Vec<Strategy>,
    pub table: TableSettings,
}

impl EstimateTableSettings {
    /// Check every setting against `m`; the error names the first that
    /// cannot be used.
    pub fn check(&self, m: &Material) -> Result<CheckedSettings, SettingsError> {
        if self.samples < 2 {
            return Err(SettingsError::new(
                Setting::Samples,
                self.samples,
                "an estimate with a variance needs at least 2 samples",
            ));
        }
        let mis_bsdf = match &self.mis_bsdf {
            Some(name) => {
                let s: BsdfStrategy = name.parse().map_err(|_| {
                    SettingsError::new(
                        Setting::MisBsdf,
                        "",
                        format!(
                            "unknown strategy `{name}`, expected one of: {}",
                            BsdfStrategy::names()
                        ),
                    )
                })?;
                m.check(s)
                    .map_err(|e| SettingsError::new(Setting::MisBsdf, "", e.to_string()))?;
                s
            }
            None => m.best_bsdf_strategy(),
        };
        let (b, l) = self.mis_samples;
        let counts = 1..=MAX_MIS_SAMPLES;
        if !counts.contains(&b) || !counts.contains(&l) {
            return Err(SettingsError::new(
                Setting::MisSamples,
                format!("{b},{l}"),
                format!("expected two counts BSDF,LIGHT, each 1 to {MAX_MIS_SAMPLES}"),
            ));
        }
        let strategies = Strategy::parse_list(
            self.strategies.iter().map(String::as_str),
            m,
            mis_bsdf,
            b,
            l,
        )
        .map_err(|e| SettingsError::new(Setting::Strategies, "", e.to_string()))?;
        if strategies.is_empty() {
            return Err(SettingsError::new(
                Setting::Strategies,
                "",
                "the list is empty",
            ));
        }
        let sequence: Sequence = self.sequence.parse().map_err(|_| {
            SettingsError::new(
                Setting::Sequence,
                "",
                format!(
                    "unknown sequence `{}`, expected independent, stratified or sobol",
                    self.sequence
                ),
            )
        })?;
        if sequence != Sequence::Independent {
            if self.replicas < 2 {
                return Err(SettingsError::new(
                    Setting::Replicas,
                    self.replicas,
                    "a standard error from replicas needs at least 2 of them",
                ));
            }
            if self.samples < self.replicas {
                return Err(SettingsError {
                    see: Some((Setting::Replicas, self.replicas.to_string())),
                    ..SettingsError::new(
                        Setting::Samples,
                        self.samples,
                        format!(
                            "under the {sequence} sequence the standard error comes from {{see}} \
                             independently randomized replicas, so at least {} samples are needed",
                            self.replicas
                        ),
                    )
                });
            }
        }
        Ok(CheckedSettings {
            strategies,
            table: TableSettings {
                sequence,
                samples: self.samples,
                seed: self.seed,
                replicas: self.replicas,
            },
        })
    }
}

/// The table that settings checked for `m` ([`EstimateTableSettings::check`])
/// ask for at `sp` under `light`: run ([`run_table`]), and refused if
/// a row is not a finite number.
pub fn estimate_table(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    checked: &CheckedSettings,
    progress: &dyn Progress,
    clock: &dyn Clock,
) -> Result<Table, SettingsError> {
    let table = run_table(
        m,
        sp,
        light,
        &checked.strategies,
        checked.table,
        progress,
        clock,
    )
    .map_err(|e| SettingsError {
        setting: None,
        value: String::new(),
        message: e.to_string(),
        see: None,
    })?;
    for row in &table.strategies {
        if !row.mean.iter().chain(&row.stderr).all(|v| v.is_finite()) || !row.variance.is_finite() {
            return Err(SettingsError {
                setting: None,
                value: String::new(),
                see: None,
                message: format!(
                    "strategy {}: the estimate is not a finite number (mean {:?}, variance {})",
                    row.name, row.mean, row.variance
                ),
            });
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> EstimateTableSettings {
        EstimateTableSettings {
            strategies: vec!["all".into()],
            mis_bsdf: None,
            mis_samples: (1, 1),
            samples: 1000,
            sequence: "independent".into(),
            seed: 1,
            replicas: 16,
        }
    }

    #[test]
    fn each_bad_setting_is_named() {
        let m = Material::load(r#"{"type":"phong","exponent":20}"#).unwrap();
        assert!(settings().check(&m).is_ok());
        let cases: [(EstimateTableSettings, Setting); 6] = [
            (
                EstimateTableSettings {
                    samples: 1,
                    ..settings()
                },
                Setting::Samples,
            ),
            (
                EstimateTableSettings {
                    mis_bsdf: Some("vndf".into()),
                    ..settings()
                },
                Setting::MisBsdf,
            ),
            (
                EstimateTableSettings {
                    mis_samples: (0, 1),
                    ..settings()
                },
                Setting::MisSamples,
            ),
            (
                EstimateTableSettings {
                    strategies: vec!["bogus".into()],
                    ..settings()
                },
                Setting::Strategies,
            ),
            (
                EstimateTableSettings {
                    sequence: "halton".into(),
                    ..settings()
                },
                Setting::Sequence,
            ),
            (
                EstimateTableSettings {
                    sequence: "sobol".into(),
                    replicas: 1,
                    ..settings()
                },
                Setting::Replicas,
            ),
        ];
        for (s, want) in cases {
            let e = s.check(&m).unwrap_err();
            assert_eq!(e.setting, Some(want), "{e:?}");
            let text = e.named(|_| "SETTING");
            assert!(text.starts_with("SETTING"), "{text}");
        }
        // A message that names another setting names it in the caller's words.
        let e = EstimateTableSettings {
            sequence: "sobol".into(),
            samples: 8,
            ..settings()
        }
        .check(&m)
        .unwrap_err();
        let text = e.named(|s| {
            if s == Setting::Replicas {
                "--replicas"
            } else {
                "--samples"
            }
        });
        assert!(
            text.starts_with("--samples 8: ") && text.contains("--replicas 16"),
            "{text}"
        );
    }
}
