//! Writing a two-part mould directory: mould1.stl, mould2.stl, their
//! preview pictures, the channel files and mould.json, replaced as a whole.

use super::{stl, MouldError, MouldFile, MouldSet, MouldSummary, SUMMARY_FILE};
use crate::io::FileError;
use std::path::Path;

impl MouldSet {
    /// Writes the mould directory `dir` as a whole: its files are written
    /// into a staging directory beside it, which then replaces `dir`
    /// ([`crate::io::write_dir_replacing`]), so a killed run leaves no
    /// partial `dir` (and an earlier one whole). `dir` must be new, empty or
    /// an earlier mould directory (it has [`SUMMARY_FILE`]).
    pub fn write_dir(&self, dir: &Path) -> Result<MouldSummary, MouldError> {
        write_mould_dir(dir, |staging| self.write_all(staging))
    }

    /// Writes mould1.stl, mould2.stl, mould1.png, mould2.png, channel.csv and
    /// mould.json into `dir` (created if missing), in place: [`MouldSet::write_dir`]
    /// is what `cablemap mould` uses; `design --moulds` writes them among
    /// its own files.
    pub fn write_all(&self, dir: &Path) -> Result<MouldSummary, MouldError> {
        std::fs::create_dir_all(dir).map_err(FileError::on("creating", dir))?;
        let m = &self.moulds;
        let channels = m.channels();
        let header = match channels {
            [one] => format!("y=[{}]", one.control_points_mm().iter().map(|y| format!("{y:.3}")).collect::<Vec<_>>().join(",")),
            several => format!("{} channels", several.len()),
        };
        let mut files = Vec::new();
        for number in [1u8, 2] {
            let (mesh, placed) = self.plate(number);
            let title = format!("cablemap mould{number}, units mm, L={} r={} {header}", m.length_mm(), m.radius_mm());
            let name = format!("mould{number}.stl");
            let path = dir.join(&name);
            crate::io::write_atomic(&path, &stl::to_bytes(&mesh, &title)).map_err(FileError::on("writing", &path))?;
            crate::plot::draw_mould(&dir.join(format!("mould{number}.png")), self, number)?;
            files.push(MouldFile { file: name, parts: placed });
        }
        let mut channel_files = Vec::new();
        for (k, routing) in channels.iter().enumerate() {
            // One planar channel: the thesis's channel.csv; several: each
            // cable's channel_K.csv, as every actuator's channels are written.
            let (name, csv) = match channels {
                [one] => ("channel.csv".to_string(), one.channel_csv()),
                _ => (crate::model::cable::channel_file_name(k), crate::model::cable::Channel::in_plane(routing).csv(m.length_mm())),
            };
            let path = dir.join(&name);
            crate::io::write_atomic(&path, csv.as_bytes()).map_err(FileError::on("writing", &path))?;
            channel_files.push(name);
        }
        let summary = MouldSummary {
            style: "two_part",
            routing_mm: (channels.len() == 1).then(|| channels[0].control_points_mm()),
            channels_y_mm: channels.iter().map(|c| c.control_points_mm()).collect(),
            channel_files,
            length_mm: m.length_mm(),
            radius_mm: m.radius_mm(),
            params: m.params().clone(),
            channel_length_mm: (0..channels.len()).map(|k| m.channel_length_mm(k)).sum(),
            files,
            mould1_cavity_mm3: self.cavity_volume_mm3(1),
            mould1_body_mm3: self.body_volume_mm3(1),
            mould2_cavity_mm3: self.cavity_volume_mm3(2),
            mould2_body_mm3: self.body_volume_mm3(2),
        };
        let path = dir.join(SUMMARY_FILE);
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises") + "\n";
        crate::io::write_atomic(&path, json.as_bytes()).map_err(FileError::on("writing", &path))?;
        Ok(summary)
    }
}

/// Writes the mould directory `dir` as a whole with `write` (into a
/// staging directory beside it, which then replaces `dir`,
/// [`crate::io::write_dir_replacing`]): a killed run leaves no partial
/// `dir`. `dir` must be new, empty or an earlier mould directory (it has
/// [`SUMMARY_FILE`]).
pub(super) fn write_mould_dir<T>(dir: &Path, write: impl FnOnce(&Path) -> Result<T, MouldError>) -> Result<T, MouldError> {
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).filter(|n| n != "." && n != "..");
    let Some(name) = name else {
        return Err(MouldError::OutUnnamed { path: dir.to_path_buf() });
    };
    let holds_files = std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_some());
    if holds_files && !dir.join(SUMMARY_FILE).is_file() {
        return Err(MouldError::NotAMouldDir { path: dir.to_path_buf() });
    }
    crate::io::write_dir_replacing(dir, &name, write, |step, path, source| {
        let what = match step {
            crate::io::DirStep::Create => "creating",
            crate::io::DirStep::Replace => "putting the new moulds in place at",
        };
        FileError::new(what, path, source).into()
    })
}
