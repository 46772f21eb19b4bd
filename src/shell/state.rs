//! The engine's learnt state on disk (shell): where it is kept, written atomically, read back. The
//! file is a magic line and the postcard encoding of [`EngineState`]; what it may hold and when it is
//! taken is the core's ([`crate::engine::state`]).

use crate::engine::state::EngineState;
use crate::settings::ShipcastConfig;
use std::path::{Path, PathBuf};

/// The state file's name in its directory.
pub const FILE_NAME: &str = "shipcast.state";

/// What every state file starts with (its format's version is the core's `STATE_VERSION`, inside).
const MAGIC: &[u8] = b"shipcast state\n";

/// Where the state is kept: `[state] dir` (relative to the config file), else systemd's
/// `STATE_DIRECTORY` (the first of its list), else nowhere.
pub fn path(cfg: &ShipcastConfig) -> Option<PathBuf> {
    let dir = if cfg.state.dir.is_empty() {
        let env = std::env::var("STATE_DIRECTORY").ok()?;
        PathBuf::from(env.split(':').next()?)
    } else {
        cfg.dir.join(&cfg.state.dir)
    };
    Some(dir.join(FILE_NAME))
}

/// Writes the state to `path` atomically: a temporary file beside it, synced, then renamed over it.
pub fn write(path: &Path, state: &EngineState) -> Result<(), String> {
    let mut bytes = MAGIC.to_vec();
    let body = postcard::to_stdvec(state).map_err(|e| format!("{}: encoding the state: {e}", path.display()))?;
    bytes.extend_from_slice(&body);
    let tmp = path.with_extension("state.tmp");
    let io = |e: std::io::Error, what: &str| format!("{}: {what}: {e}", path.display());
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| io(e, "making its directory"))?;
    }
    {
        use std::io::Write;
        let mut f = std::fs::File::create(&tmp).map_err(|e| io(e, "creating the temporary file"))?;
        f.write_all(&bytes).map_err(|e| io(e, "writing"))?;
        f.sync_all().map_err(|e| io(e, "syncing"))?;
    }
    std::fs::rename(&tmp, path).map_err(|e| io(e, "renaming the temporary file over it"))
}

/// Reads the state at `path`: None when there is none; an error naming the file when it cannot be
/// read or is not a state this shipcast wrote (corrupt, truncated, another format).
pub fn read(path: &Path) -> Result<Option<EngineState>, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let Some(body) = bytes.strip_prefix(MAGIC) else {
        return Err(format!(
            "{}: not a shipcast state file (its first line)",
            path.display()
        ));
    };
    postcard::from_bytes(body)
        .map(Some)
        .map_err(|e| format!("{}: corrupt ({} bytes): {e}", path.display(), bytes.len()))
}
