//! `render!`: the one way a figure reaches its file (SVG or PNG by the extension), with every
//! failure naming the file. Declared first in `plot`, so every figure module can use it.

/// Draws `$body` (which sees the drawing area as `$root` and whether the target is SVG as
/// `$svg`, and returns this crate's `Result<()>`) on a PNG or SVG backend chosen by the extension
/// of `$path`, then writes the file; every failure is an `Error::Draw` or `Error::UnknownFormat`
/// naming the file. Returns from the enclosing function on failure, else evaluates to `Ok(())`.
macro_rules! render {
    ($path:expr, $size:expr, |$root:ident, $svg:ident| $body:expr) => {{
        let path: &std::path::Path = $path;
        let draw = |message: String| $crate::error::Error::Draw {
            file: path.to_path_buf(),
            message,
        };
        match $crate::plot::format::Format::from_path(path) {
            Some(format) => {
                $crate::plot::fonts::register();
                let $svg = format == $crate::plot::format::Format::Svg;
                // Drawn into a temporary beside the figure (with its extension, which picks the
                // encoder) and renamed onto it: the figure's name never holds a partial file,
                // and a failure leaves nothing (issue 66).
                let tmp = $crate::plot::render::temp_figure(path);
                let drawn = (|| -> $crate::error::Result<()> {
                    std::fs::File::create(&tmp)
                        .map_err($crate::error::Error::io(path, "cannot write the figure"))?;
                    if $svg {
                        let $root = $crate::plot::fonts::Glyphs(
                            plotters::prelude::SVGBackend::new(&tmp, $size),
                        )
                        .into_drawing_area();
                        $body.map_err(|e: $crate::error::Error| draw(e.chain_text()))?;
                        $root
                            .present()
                            .map_err(|e| $crate::plot::render::present_error(path, &e))?;
                    } else {
                        let $root = $crate::plot::fonts::Glyphs(
                            plotters::prelude::BitMapBackend::new(&tmp, $size),
                        )
                        .into_drawing_area();
                        $body.map_err(|e: $crate::error::Error| draw(e.chain_text()))?;
                        $root
                            .present()
                            .map_err(|e| $crate::plot::render::present_error(path, &e))?;
                    }
                    $crate::plot::render::finish(&tmp, path)
                })();
                if drawn.is_err() {
                    let _ = std::fs::remove_file(&tmp);
                }
                drawn?;
            }
            None => {
                return Err($crate::error::Error::UnknownFormat {
                    file: path.to_path_buf(),
                    message: "unknown file type; use .svg or .png",
                });
            }
        }
        Ok(())
    }};
}

/// The temporary a figure is drawn into: hidden, beside it, ending in its extension.
pub(crate) fn temp_figure(path: &std::path::Path) -> std::path::PathBuf {
    let tmp = hpge_files::temp_beside(path);
    match path.extension() {
        Some(ext) => {
            let mut e = std::ffi::OsString::from("tmp.");
            e.push(ext);
            tmp.with_extension(e)
        }
        None => tmp,
    }
}

/// Syncs the drawn temporary `tmp` and renames it onto the figure `path`.
pub(crate) fn finish(tmp: &std::path::Path, path: &std::path::Path) -> crate::error::Result<()> {
    std::fs::File::open(tmp)
        .and_then(|f| f.sync_all())
        .and_then(|()| std::fs::rename(tmp, path))
        .map_err(crate::error::Error::io(path, "cannot write the figure"))
}

/// A failed `present()` (the file write) as an error naming the figure: the operating system's
/// message where the backend's error carries one (plotters prints only debug values such as
/// `ImageError(IoError(Os { code: 28, .. }))`), else the backend's text.
pub(crate) fn present_error<E: std::fmt::Debug + std::fmt::Display>(
    path: &std::path::Path,
    e: &E,
) -> crate::error::Error {
    let debug = format!("{e:?}");
    let code = debug.split("code: ").nth(1).and_then(|rest| {
        rest.split(|c: char| !c.is_ascii_digit())
            .next()
            .and_then(|d| d.parse::<i32>().ok())
    });
    match code {
        Some(code) => crate::error::Error::Io {
            file: path.to_path_buf(),
            action: "cannot write the figure",
            source: std::io::Error::from_raw_os_error(code),
        },
        None => crate::error::Error::Draw {
            file: path.to_path_buf(),
            message: e.to_string(),
        },
    }
}
