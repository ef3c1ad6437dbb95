//! The fingerprint of a resolved experiment: SHA-256 (FIPS 180-4, by the
//! `sha2` crate) of the experiment file's text and of the base model it
//! resolves to, stored in every shard so that a merge refuses shards made
//! from another experiment.

use super::ExperimentError;
use super::spec::Experiment;

/// SHA-256 of `data`, as 64 lowercase hex digits (the `sha2` crate).
pub fn sha256_hex(data: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(data).iter().map(|b| format!("{b:02x}")).collect()
}

/// The fingerprint of `exp` resolved on `base_model`: SHA-256 of the
/// experiment file's bytes, a NUL, and the base model as TOML. Anything
/// that changes a run (a sweep, a `[set]` value, the model file or the
/// files a model sweep names) or the
/// outputs (a plot, a check) changes it.
pub fn experiment_fingerprint(exp: &Experiment, base_model: &toml::Table) -> Result<String, ExperimentError> {
    let text = crate::limits::read_input(&exp.source, crate::limits::InputKind::Text).map_err(|source| {
        ExperimentError::Io {
            path: exp.source.clone(),
            source,
        }
    })?;
    let mut data = text;
    data.push(0);
    data.extend_from_slice(base_model.to_string().as_bytes());
    // The model files a `[[sweep]] key = "model"` runs on.
    for path in exp.swept_files() {
        let src = super::spec::model_source(&path)?;
        data.push(0);
        data.extend_from_slice(src.text.as_bytes());
        // and the hardware file it names, as merged into it
        if src.own_table()?.contains_key(crate::config::HARDWARE_KEY) {
            data.push(0);
            data.extend_from_slice(src.table()?.to_string().as_bytes());
        }
    }
    Ok(sha256_hex(&data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fips_180_test_vectors() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_hex(b"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"
        );
        // A million 'a's: many blocks.
        assert_eq!(
            sha256_hex(&vec![b'a'; 1_000_000]),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0"
        );
    }
}
