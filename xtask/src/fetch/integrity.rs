//! Hashing helpers: SHA-256 hex digests for the extracted files and the
//! npm `sha512-<base64>` integrity strings (Subresource Integrity format) for
//! the package tarball.

use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine;
use sha2::{Digest, Sha256, Sha512};

/// Returns the lowercase hexadecimal SHA-256 digest of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

/// Checks that `bytes` hash to the digest in an npm integrity string such as
/// `sha512-7qDw...==`.
///
/// Only the `sha512` algorithm is accepted, because that is what the npm
/// registry publishes and what the lock file records. On a mismatch the error
/// names both the expected and the actual integrity string.
pub fn verify_sri_sha512(bytes: &[u8], integrity: &str) -> Result<(), String> {
    let expected = parse_sri_sha512(integrity)?;
    let actual = Sha512::digest(bytes);
    if actual.as_slice() == expected.as_slice() {
        Ok(())
    } else {
        Err(format!(
            "SHA-512 mismatch: expected {integrity}, actual sha512-{}",
            BASE64.encode(actual)
        ))
    }
}

/// Decodes the digest of a `sha512-<base64>` integrity string and checks its length.
pub fn parse_sri_sha512(integrity: &str) -> Result<Vec<u8>, String> {
    let encoded = integrity
        .trim()
        .strip_prefix("sha512-")
        .ok_or_else(|| format!("integrity `{integrity}` does not start with `sha512-`"))?;
    // Standard, padded base64 (RFC 4648, section 4), canonical only: one accepted spelling per digest.
    let digest = BASE64
        .decode(encoded)
        .map_err(|e| format!("integrity `{integrity}` is not valid base64: {e}"))?;
    if digest.len() != 64 {
        return Err(format!(
            "integrity `{integrity}` decodes to {} bytes, but a SHA-512 digest has 64",
            digest.len()
        ));
    }
    Ok(digest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sri_rejects_malformed_base64() {
        let digest = &ABC_SRI["sha512-".len()..];
        for (bad, why) in [
            (format!("sha512-{}", &digest[..digest.len() - 1]), "length not a multiple of 4"),
            (format!("sha512-{}", digest.replace('+', "-")), "URL-safe alphabet"),
            (format!("sha512-{}", digest.replace("kn", "k=")), "padding in the middle"),
            (format!("sha512-{}", digest.replace("nw==", "nx==")), "non-zero trailing bits"),
        ] {
            let error = parse_sri_sha512(&bad).unwrap_err();
            assert!(error.contains("not valid base64"), "{why}: {error}");
        }
    }

    #[test]
    fn sha256_hex_matches_known_digest() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    /// The npm integrity string of the bytes `abc` (SHA-512 from FIPS 180-2, in base64).
    const ABC_SRI: &str =
        "sha512-3a81oZNherrMQXNJriBBMRLm+k6JqX6iCp7u5ktV05ohkpkqJ0/BqDa6PCOj/uu9RU1EI2Q86A4qmslPpUyknw==";

    #[test]
    fn sri_accepts_matching_bytes() {
        assert_eq!(verify_sri_sha512(b"abc", ABC_SRI), Ok(()));
    }

    #[test]
    fn sri_rejects_different_bytes_and_names_both_digests() {
        let error = verify_sri_sha512(b"abd", ABC_SRI).unwrap_err();
        assert!(error.contains(ABC_SRI), "{error}");
        assert!(error.contains("actual sha512-"), "{error}");
    }

    #[test]
    fn sri_rejects_other_algorithms_and_truncated_digests() {
        assert!(parse_sri_sha512("sha256-ungWv48Bz+pBQUDeXa4iI7ADYaOWF3qctBD/YfIAFa0=").is_err());
        assert!(
            parse_sri_sha512("sha512-Zm9vYmFy").is_err(),
            "six bytes is not a SHA-512 digest"
        );
    }

    #[test]
    fn pinned_package_integrity_is_well_formed() {
        let digest = parse_sri_sha512(
            "sha512-7qDwdkYRKIGRBk0gKhY5C3olQ0wRHTCoZj4FbzD1GmXF5xGaZcv/OatvFa73H7yyq3LxWxTKVteELlbbyziyLg==",
        )
        .expect("the pinned integrity decodes");
        assert_eq!(digest.len(), 64);
        assert_eq!(&digest[..4], &[0xee, 0xa0, 0xf0, 0x76]);
    }
}
