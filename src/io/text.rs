//! Line and token scanning shared by the text formats (OBJ, OFF).

use super::IoError;

/// Splits `bytes` into lines numbered from 1, accepting `\n`, `\r\n` and a
/// lone `\r` as line ends (files edited on several systems mix them). A line
/// that is not UTF-8 or holds a NUL byte is an error: the file is binary, not
/// the text format its name claims.
pub fn lines<'a>(
    bytes: &'a [u8],
    file: &'a str,
) -> impl Iterator<Item = Result<(usize, &'a str), IoError>> + 'a {
    let mut rest = bytes;
    let mut number = 0usize;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let end = rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(rest.len());
        let line = &rest[..end];
        let skip = match (rest.get(end), rest.get(end + 1)) {
            (Some(b'\r'), Some(b'\n')) => 2,
            (Some(_), _) => 1,
            (None, _) => 0,
        };
        rest = &rest[end + skip..];
        if line.contains(&0) {
            return Some(Err(IoError::at_line(
                file,
                number,
                "binary data (NUL byte) in a text file",
            )));
        }
        Some(match std::str::from_utf8(line) {
            Ok(s) => Ok((number, s)),
            Err(_) => Err(IoError::at_line(
                file,
                number,
                "the line is not valid UTF-8 text",
            )),
        })
    })
}

/// Parses a coordinate, rejecting NaN and infinities by name.
pub fn coordinate(token: &str, file: &str, line: usize) -> Result<f64, IoError> {
    let value: f64 = token
        .parse()
        .map_err(|_| IoError::at_line(file, line, format!("'{token}' is not a number")))?;
    if !value.is_finite() {
        return Err(IoError::at_line(
            file,
            line,
            format!("coordinate '{token}' is not finite"),
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixed_line_endings_are_counted_once() {
        let text = b"a\r\nb\nc\rd";
        let got: Vec<_> = lines(text, "t").map(|r| r.unwrap()).collect();
        assert_eq!(got, vec![(1, "a"), (2, "b"), (3, "c"), (4, "d")]);
    }

    #[test]
    fn nan_and_inf_are_rejected() {
        assert!(coordinate("nan", "t", 1).is_err());
        assert!(coordinate("-inf", "t", 1).is_err());
        assert!(coordinate("1e400", "t", 1).is_err());
        assert_eq!(coordinate("-2.5e-3", "t", 1).unwrap(), -2.5e-3);
    }
}
