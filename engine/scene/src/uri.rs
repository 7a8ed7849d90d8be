//! glTF URIs: `data:` URIs with base64 payloads, and percent-encoded relative file paths.

/// A decoded `data:` URI: its MIME type and bytes; `None` when `uri` is not a data URI.
/// `Some(Err(..))` says why a data URI does not decode.
pub(crate) fn decode_data_uri(uri: &str) -> Option<Result<(String, Vec<u8>), String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((header, payload)) = rest.split_once(',') else {
        return Some(Err("data URI without ','".to_string()));
    };
    let Some(mime) = header.strip_suffix(";base64") else {
        return Some(Err("data URI is not base64".to_string()));
    };
    Some(base64(payload).map(|bytes| (mime.to_string(), bytes)))
}

/// Standard base64 (padding optional, whitespace ignored).
fn base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for c in text.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' | b' ' | b'\n' | b'\r' | b'\t' => continue,
            other => return Err(format!("byte 0x{other:02x} is not base64")),
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// A relative URI reference as a file path: `%XX` escapes decoded (invalid ones kept).
pub(crate) fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok());
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_and_escapes() {
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,SGVsbG8="),
            Some(Ok((
                "application/octet-stream".to_string(),
                b"Hello".to_vec()
            )))
        );
        assert_eq!(
            decode_data_uri("data:x;base64,SGk"),
            Some(Ok(("x".to_string(), b"Hi".to_vec())))
        );
        assert_eq!(decode_data_uri("file.bin"), None);
        assert_eq!(
            decode_data_uri("data:x,abc"),
            Some(Err("data URI is not base64".to_string()))
        );
        assert_eq!(percent_decode("a%20b%2x.png"), "a b%2x.png");
    }
}
