//! Text files as users have them: photometric and weather files come from many tools, older
//! ones in Latin-1 (a city or a luminaire named with an accent), newer ones in UTF-8.

/// The file's text: UTF-8 as it is, anything else byte by byte as Latin-1 (every byte is a
/// Latin-1 character, so this never fails and loses nothing).
pub fn decode(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| char::from(b)).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::decode;

    #[test]
    fn utf8_is_kept_and_other_bytes_read_as_latin1() {
        assert_eq!(decode("Zürich".as_bytes()), "Zürich");
        assert_eq!(decode(b"Z\xfcrich"), "Zürich");
        assert_eq!(decode(b"S\xe3o Paulo \xff"), "São Paulo ÿ");
    }
}
