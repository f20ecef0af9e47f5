//! The figure formats (chosen by a file's extension) and the check of an output path before any
//! work.

use std::path::Path;

use crate::error::{Error, Result};

/// Output format, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics (bitmap).
    Png,
}

impl Format {
    /// `.svg` or `.png` (case-insensitive); anything else is `None`.
    pub fn from_path(path: &Path) -> Option<Format> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "svg" => Some(Format::Svg),
            "png" => Some(Format::Png),
            _ => None,
        }
    }
}

/// Checks an output path before any work: a known extension and an existing folder. `flag` names
/// the option in the message.
///
/// ```
/// use std::path::Path;
/// use hpge_reports::plot::{Format, check_output};
/// assert_eq!(Format::from_path(Path::new("cv.PNG")), Some(Format::Png));
/// let dir = std::env::temp_dir();
/// assert!(check_output(&dir.join("cv.svg"), "--plot").is_ok());
/// let e = check_output(&dir.join("cv.jpg"), "--plot").unwrap_err().to_string();
/// assert!(e.contains("--plot") && e.contains(".svg or .png"), "{e}");
/// assert!(check_output(&dir.join("no/such/folder/cv.svg"), "--plot").is_err());
/// ```
pub fn check_output(path: &Path, flag: &str) -> Result<()> {
    let output = |message: String| Error::Output {
        flag: flag.to_string(),
        file: path.to_path_buf(),
        message,
    };
    if Format::from_path(path).is_none() {
        return Err(output(
            "unknown file type; use a name ending in .svg or .png".into(),
        ));
    }
    if path.is_dir() {
        return Err(output(
            "is a folder; give a file name ending in .svg or .png".into(),
        ));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        return Err(output(format!(
            "the folder {} does not exist",
            dir.display()
        )));
    }
    Ok(())
}
