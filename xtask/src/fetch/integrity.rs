//! Hashing helpers: SHA-256 hex digests for the extracted files and the
//! npm `sha512-<base64>` integrity strings (Subresource Integrity format) for
//! the package tarball.

use sha2::{Digest, Sha256, Sha512};

/// Returns the lowercase hexadecimal SHA-256 digest of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    to_hex(&Sha256::digest(bytes))
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
            base64_encode(&actual)
        ))
    }
}

/// Decodes the digest of a `sha512-<base64>` integrity string and checks its length.
pub fn parse_sri_sha512(integrity: &str) -> Result<Vec<u8>, String> {
    let encoded = integrity
        .trim()
        .strip_prefix("sha512-")
        .ok_or_else(|| format!("integrity `{integrity}` does not start with `sha512-`"))?;
    let digest = base64_decode(encoded)
        .map_err(|e| format!("integrity `{integrity}` is not valid base64: {e}"))?;
    if digest.len() != 64 {
        return Err(format!(
            "integrity `{integrity}` decodes to {} bytes, but a SHA-512 digest has 64",
            digest.len()
        ));
    }
    Ok(digest)
}

/// The standard base64 alphabet (RFC 4648, section 4), which npm uses.
const BASE64_ALPHABET: &[u8; 64] =
    b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Decodes standard, padded base64 (RFC 4648, section 4).
///
/// The input length must be a multiple of four, `=` may appear only as one or
/// two final padding characters, and the unused low bits of the last symbol
/// must be zero, so every digest has exactly one accepted spelling.
pub fn base64_decode(input: &str) -> Result<Vec<u8>, String> {
    let bytes = input.as_bytes();
    if !bytes.len().is_multiple_of(4) {
        return Err(format!("length {} is not a multiple of 4", bytes.len()));
    }
    let padding = bytes.iter().rev().take_while(|&&b| b == b'=').count();
    if padding > 2 {
        return Err(format!(
            "{padding} padding characters, at most 2 are allowed"
        ));
    }
    let body = &bytes[..bytes.len() - padding];

    let mut out = Vec::with_capacity(body.len() * 3 / 4);
    let mut buffer: u32 = 0;
    let mut bits = 0u32;
    for (index, &symbol) in body.iter().enumerate() {
        let value = BASE64_ALPHABET
            .iter()
            .position(|&a| a == symbol)
            .ok_or_else(|| format!("invalid character {:?} at offset {index}", symbol as char))?;
        buffer = (buffer << 6) | value as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((buffer >> bits) as u8);
            buffer &= (1 << bits) - 1;
        }
    }
    // With one `=` two bits are left over, with two `=` four bits; both must be zero.
    if buffer != 0 {
        return Err("non-zero trailing bits before the padding".to_string());
    }
    Ok(out)
}

/// Encodes bytes as standard, padded base64; used only to print actual digests in errors.
pub fn base64_encode(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let group = match *chunk {
            [a] => u32::from(a) << 16,
            [a, b] => (u32::from(a) << 16) | (u32::from(b) << 8),
            [a, b, c] => (u32::from(a) << 16) | (u32::from(b) << 8) | u32::from(c),
            _ => unreachable!("chunks(3) yields one to three bytes"),
        };
        for position in 0..4 {
            if position <= chunk.len() {
                let index = (group >> (18 - 6 * position)) & 0x3f;
                out.push(BASE64_ALPHABET[index as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Formats bytes as lowercase hexadecimal.
fn to_hex(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mut out = String::with_capacity(bytes.len() * 2);
    for &byte in bytes {
        out.push(DIGITS[usize::from(byte >> 4)] as char);
        out.push(DIGITS[usize::from(byte & 0x0f)] as char);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_rfc4648_test_vectors() {
        // The test vectors from RFC 4648, section 10.
        let vectors = [
            ("", ""),
            ("Zg==", "f"),
            ("Zm8=", "fo"),
            ("Zm9v", "foo"),
            ("Zm9vYg==", "foob"),
            ("Zm9vYmE=", "fooba"),
            ("Zm9vYmFy", "foobar"),
        ];
        for (encoded, decoded) in vectors {
            assert_eq!(
                base64_decode(encoded).as_deref(),
                Ok(decoded.as_bytes()),
                "{encoded}"
            );
            assert_eq!(base64_encode(decoded.as_bytes()), encoded, "{decoded}");
        }
    }

    #[test]
    fn base64_round_trips_every_byte_value() {
        let all: Vec<u8> = (0..=255).collect();
        for len in [0, 1, 2, 3, 64, 255, 256] {
            let encoded = base64_encode(&all[..len]);
            assert_eq!(base64_decode(&encoded).as_deref(), Ok(&all[..len]));
        }
    }

    #[test]
    fn base64_rejects_malformed_input() {
        assert!(base64_decode("Zg=").is_err(), "length not a multiple of 4");
        assert!(base64_decode("Z===").is_err(), "three padding characters");
        assert!(
            base64_decode("Zm9-").is_err(),
            "URL-safe alphabet is not accepted"
        );
        assert!(base64_decode("Zm=v").is_err(), "padding in the middle");
        assert!(base64_decode("Zh==").is_err(), "non-zero trailing bits");
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
