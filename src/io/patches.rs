//! Per-face patch ids (`remesh --write-patches`, `render --patches`): a text file with one line
//! per face of the output mesh, in face order, holding the 0-based id of the patch that made
//! the face (Algorithm 1's order of creation) or `-` for a face that no patch made (an input
//! face kept as it was). Lines starting with `#` are comments.

use super::{IoError, Syntax};
use crate::ids::PatchId;
use std::path::Path;

const F: &str = "patches";

/// The file's bytes for `face_patch` (one entry per face).
pub fn face_patches_bytes(face_patch: &[Option<PatchId>]) -> Vec<u8> {
    let mut s = String::from(
        "# conemesh face patches: one line per output face, the patch that made it (0-based), - for none\n",
    );
    for p in face_patch {
        match p {
            Some(p) => s.push_str(&format!("{}\n", p.0)),
            None => s.push_str("-\n"),
        }
    }
    s.into_bytes()
}

/// Read a patch file (module docs); the count is checked by whoever pairs it with a mesh.
pub fn read_face_patches(path: &Path) -> Result<Vec<Option<PatchId>>, IoError> {
    let p = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|error| IoError::Os {
        path: p.clone(),
        error,
    })?;
    read_face_patches_bytes(&bytes, &p)
}

/// [`read_face_patches`] on the bytes of a file; `path` only names the source in errors.
pub fn read_face_patches_bytes(bytes: &[u8], path: &str) -> Result<Vec<Option<PatchId>>, IoError> {
    let text = std::str::from_utf8(bytes).map_err(|e| IoError::Parse {
        path: path.to_string(),
        format: F,
        line: 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        defect: Syntax::NotUtf8,
    })?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('#') {
            continue;
        }
        out.push(match t {
            "-" => None,
            _ => Some(PatchId(t.parse::<u32>().map_err(|_| IoError::Parse {
                path: path.to_string(),
                format: F,
                line: i + 1,
                defect: Syntax::NotAPatchId {
                    found: super::printable(t.as_bytes()),
                },
            })?)),
        });
    }
    if out.is_empty() {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patch_files_round_trip_and_bad_lines_are_named() -> Result<(), IoError> {
        let ids = vec![Some(PatchId(3)), None, Some(PatchId(0))];
        let bytes = face_patches_bytes(&ids);
        assert_eq!(read_face_patches_bytes(&bytes, "p.txt")?, ids);
        let bad = read_face_patches_bytes(b"# c\n1\nx7\n", "p.txt");
        assert!(
            matches!(&bad, Err(IoError::Parse { line: 3, .. })),
            "{bad:?}"
        );
        let empty = read_face_patches_bytes(b"# only a comment\n", "p.txt");
        assert!(matches!(empty, Err(IoError::Empty { .. })), "{empty:?}");
        Ok(())
    }
}
