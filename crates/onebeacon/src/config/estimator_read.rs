//! The reader of one flat `[[estimators]]` table into [`EstimatorSpec`] and its key
//! groups ([`super::estimator_keys`]). A key no group knows is refused while it is read,
//! with its line and the keys allowed, as `deny_unknown_fields` refuses it (serde's
//! `flatten` would lose both: it buffers the table and accepts any key).

use super::estimator::{
    CalibrationKeys, EstimatorKind, EstimatorSpec, GateKeys, NoiseKeys, ParticleKeys, PlanarKeys, SixDofKeys,
    UnicycleKeys, UsblKeys,
};
use serde::de::{Deserialize, DeserializeSeed, Deserializer, Error, MapAccess, Visitor};
use std::sync::LazyLock;

/// The keys of the table itself, besides the groups'.
const OWN_KEYS: &[&str] =
    &["kind", "name", "measurements", "filter", "ukf_alpha", "ukf_beta", "ukf_kappa", "seed", "iusbl"];

/// Every key an `[[estimators]]` table may hold.
static ALL_KEYS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    let groups = [
        NoiseKeys::KEYS,
        GateKeys::KEYS,
        CalibrationKeys::KEYS,
        UnicycleKeys::KEYS,
        SixDofKeys::KEYS,
        UsblKeys::KEYS,
        ParticleKeys::KEYS,
        PlanarKeys::KEYS,
    ];
    OWN_KEYS.iter().chain(groups.into_iter().flatten()).copied().collect()
});

impl<'de> Deserialize<'de> for EstimatorSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(TableVisitor)
    }
}

struct TableVisitor;

/// A key of [`ALL_KEYS`], refused otherwise.
struct KnownKey;

impl<'de> DeserializeSeed<'de> for KnownKey {
    type Value = &'static str;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<&'static str, D::Error> {
        d.deserialize_identifier(self)
    }
}

impl Visitor<'_> for KnownKey {
    type Value = &'static str;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a key of an [[estimators]] table")
    }

    fn visit_str<E: Error>(self, v: &str) -> Result<&'static str, E> {
        ALL_KEYS.iter().find(|k| **k == v).copied().ok_or_else(|| E::unknown_field(v, &ALL_KEYS))
    }
}

impl<'de> Visitor<'de> for TableVisitor {
    type Value = EstimatorSpec;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an [[estimators]] table")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EstimatorSpec, A::Error> {
        let mut kind: Option<EstimatorKind> = None;
        let mut e = EstimatorSpec::new(EstimatorKind::DeadReckoning);
        // an unknown key is refused as it is read, so that the error has its line
        while let Some(key) = map.next_key_seed(KnownKey)? {
            match key {
                "kind" => kind = Some(map.next_value()?),
                "name" => e.name = Some(map.next_value()?),
                "measurements" => e.measurements = Some(map.next_value()?),
                "filter" => e.filter = map.next_value()?,
                "ukf_alpha" => e.ukf_alpha = Some(map.next_value()?),
                "ukf_beta" => e.ukf_beta = Some(map.next_value()?),
                "ukf_kappa" => e.ukf_kappa = Some(map.next_value()?),
                "seed" => e.seed = Some(map.next_value()?),
                "iusbl" => e.iusbl = Some(map.next_value()?),
                k => {
                    let taken = e.noise.take(k, &mut map)?
                        || e.gating.take(k, &mut map)?
                        || e.calibration.take(k, &mut map)?
                        || e.unicycle.take(k, &mut map)?
                        || e.six_dof.take(k, &mut map)?
                        || e.usbl.take(k, &mut map)?
                        || e.particle.take(k, &mut map)?
                        || e.planar.take(k, &mut map)?;
                    if !taken {
                        return Err(A::Error::unknown_field(k, &ALL_KEYS));
                    }
                }
            }
        }
        e.kind = kind.ok_or_else(|| A::Error::missing_field("kind"))?;
        Ok(e)
    }
}

#[cfg(all(test, feature = "log"))]
mod tests {
    use super::*;
    use crate::config::estimator::ResamplerName;
    use crate::config::toml_file::deserialize;
    use serde::Serialize;

    #[derive(Debug, serde::Deserialize, Serialize)]
    struct File {
        estimators: Vec<EstimatorSpec>,
    }

    fn error(text: &str) -> String {
        deserialize::<File>(text, "f.toml").unwrap_err().to_string()
    }

    /// A key of every group read from one flat table into its group, written back flat
    /// and read again to the same spec; every key is in exactly one group.
    #[test]
    fn a_flat_table_fills_the_groups_and_round_trips() {
        let text = "[[estimators]]\nkind = \"pf\"\nname = \"a\"\nrange_sigma_m = 2\nnis_gate = 9.0\n\
                    estimate_bias = true\nq_diag = [1, 1, 1, 1, 1, 1]\nvelocity_sigma_m_s = 0.1\n\
                    usbl_floor_deg = 0.5\nparticles = 1000\nresampler = \"residual\"\n\
                    speed_coast_time_s = 4\nseed = -3\n[estimators.iusbl]\nparticles = 7\n";
        let f: File = deserialize(text, "f.toml").unwrap();
        let e = &f.estimators[0];
        assert_eq!(e.kind, EstimatorKind::Particle);
        assert_eq!(e.noise.range_sigma_m, Some(2.0));
        assert_eq!(e.gating.nis_gate, Some(9.0));
        assert_eq!(e.calibration.estimate_bias, Some(true));
        assert_eq!(e.unicycle.q_diag, Some([1.0; 6]));
        assert_eq!(e.six_dof.velocity_sigma_m_s, Some(0.1));
        assert_eq!(e.usbl.usbl_floor_deg, Some(0.5));
        assert_eq!((e.particle.particles, e.particle.resampler), (Some(1000), Some(ResamplerName::Residual)));
        assert_eq!(e.planar.speed_coast_time_s, Some(4.0));
        assert_eq!((e.seed, e.iusbl.as_ref().map(|k| k.particles)), (Some(-3), Some(7)));
        let written = toml::to_string(&f).unwrap();
        let again: File = deserialize(&written, "written").unwrap();
        assert_eq!(again.estimators, f.estimators, "{written}");
        let mut keys = ALL_KEYS.clone();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), ALL_KEYS.len(), "a key in two groups");
    }

    /// What `deny_unknown_fields` gave: the key, its line and the keys allowed; a wrong
    /// type names the key and its line; `kind` is required.
    #[test]
    fn a_bad_key_is_named_with_its_line() {
        let e = error("[[estimators]]\nkind = \"rosb\"\n\nrange_sigma_mm = 2\n");
        assert!(e.starts_with("f.toml: line 4: key `estimators[0]"), "{e}");
        assert!(e.contains("unknown field `range_sigma_mm`, expected one of `kind`"), "{e}");
        assert!(e.contains("`range_sigma_m`") && e.contains("`speed_coast_time_s`"), "{e}");
        let e = error("[[estimators]]\nkind = \"rosb\"\nnis_gate = \"high\"\n");
        assert!(e.starts_with("f.toml: line 3: key `estimators[0].nis_gate`"), "{e}");
        let e = error("[[estimators]]\nname = \"x\"\n");
        assert!(e.contains("missing field `kind`"), "{e}");
    }
}
