//! `hpge-cv`: impurity densities of HPGe detectors from capacitance-voltage curves.
//!
//! Every error is printed as one message naming the file, key or value at fault, and the program
//! exits with code 2 (bad input); it never panics on user input. A fit that did not converge
//! exits with code 3, a fit whose exact-solver check fails after refinement with code 4, and a
//! validation study that fails its own criteria with code 1.

/// `println!` for what a command prints on stdout, returning (`?`) a
/// [`cli::stdout::StdoutError`] instead of panicking when stdout cannot be written.
macro_rules! outln {
    () => {
        $crate::cli::stdout::write_fmt(format_args!("\n"))?
    };
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!("{}\n", format_args!($($arg)*)))?
    };
}

/// `print!` as [`outln!`] is `println!`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!($($arg)*))?
    };
}

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    quiet_vulkan_device_select();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of stdout has gone (`| head`): nothing more to say, and no one to say it to.
        Err(err)
            if err
                .downcast_ref::<cli::stdout::StdoutError>()
                .is_some_and(cli::stdout::StdoutError::broken_pipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(err) if err.downcast_ref::<cli::Unconverged>().is_some() => {
            eprintln!("error: {}", message(&err));
            ExitCode::from(3)
        }
        // A study that failed its own criteria: its report is written; exit code 1.
        Err(err) if err.downcast_ref::<cli::StudyFailed>().is_some() => {
            eprintln!("{}", message(&err));
            ExitCode::from(1)
        }
        Err(err) if err.downcast_ref::<cli::ExactMismatch>().is_some() => {
            eprintln!("error: {}", message(&err));
            ExitCode::from(4)
        }
        Err(err) => {
            eprintln!("error: {}", message(&err));
            ExitCode::from(2)
        }
    }
}

/// The error with its causes joined by ": ", each cause once: the libraries' errors often put
/// their source's text into their own message (`file: cannot read the file: No such file or
/// directory (os error 2)`) and also return it as `source()`, which anyhow's `{:#}` would print
/// a second time. A cause whose text is already in the message so far is left out.
fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let part = cause.to_string();
        if text.is_empty() {
            text = part;
        } else if !text.contains(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
    }
    text
}

/// Keeps Mesa's Vulkan device-select layer (`VK_LAYER_MESA_device_select`, an implicit layer
/// Mesa installs) from asking a Wayland compositor for the default GPU when there can be none:
/// without `XDG_RUNTIME_DIR`, libwayland-client prints "error: XDG_RUNTIME_DIR is invalid or not
/// set in the environment." on every adapter enumeration, twice in a successful `--backend
/// wgpu` run, though nothing failed. The layer is switched off (`NODEVICE_SELECT=1`) only then,
/// and only when the user has not chosen a device through it (`MESA_VK_DEVICE_SELECT`) or
/// switched it themselves; wgpu ranks the adapters itself (a discrete GPU first).
fn quiet_vulkan_device_select() {
    let unset = |key: &str| std::env::var_os(key).is_none_or(|v| v.is_empty());
    let runtime_dir_ok = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| {
        std::path::Path::new(&d).is_absolute() && std::path::Path::new(&d).is_dir()
    });
    if !runtime_dir_ok
        && unset("WAYLAND_SOCKET")
        && unset("NODEVICE_SELECT")
        && unset("MESA_VK_DEVICE_SELECT")
    {
        // SAFETY: called first thing in `main`, before any other thread exists (no thread can
        // read the environment concurrently).
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

#[cfg(test)]
mod tests {
    use super::message;

    #[derive(Debug, thiserror::Error)]
    #[error("data.csv: cannot read the file: {source}")]
    struct Repeats {
        #[source]
        source: std::io::Error,
    }

    #[derive(Debug, thiserror::Error)]
    #[error("data.csv: cannot read the file")]
    struct Defers {
        #[source]
        source: std::io::Error,
    }

    fn missing() -> std::io::Error {
        std::io::Error::from_raw_os_error(2)
    }

    #[test]
    fn every_cause_is_printed_once() {
        let e = anyhow::Error::new(Repeats { source: missing() });
        let m = message(&e);
        assert_eq!(m.matches("(os error 2)").count(), 1, "{m}");
        let e = anyhow::Error::new(Defers { source: missing() });
        let m = message(&e);
        assert!(m.starts_with("data.csv: cannot read the file: "), "{m}");
        assert_eq!(m.matches("(os error 2)").count(), 1, "{m}");
        let e = anyhow::Error::new(Repeats { source: missing() }).context("--data data.csv");
        let m = message(&e);
        assert!(m.starts_with("--data data.csv: data.csv"), "{m}");
        assert_eq!(m.matches("(os error 2)").count(), 1, "{m}");
    }
}
