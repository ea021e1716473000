//! `uio-launcher export`: a recording's signals for other tools, one file (or directory) per
//! format, each in its own module — [`csv`] (one CSV per entity group), [`mcap`] (Foxglove,
//! PlotJuggler), [`npz`] (NumPy) and [`mat`] (MATLAB, scipy.io.loadmat). Every format groups
//! the series the same way ([`table::groups`]) and gives a member no value where CSV leaves its
//! cell empty. Files are staged beside their target and renamed into place ([`staged`]), so a
//! failed export leaves no half-written file.

pub mod csv;
pub mod mat;
pub mod mcap;
pub mod npz;
mod staged;
pub mod table;

pub use csv::{export, file_name, header};
pub use table::groups;

#[cfg(test)]
mod tests {
    use std::io::Read as _;

    use crate::read::{Recording, Series};

    /// Two members of one group recorded at different steps (a latency hop lagging one step).
    fn lagging() -> Recording {
        let mut r = Recording::default();
        r.series.insert(
            "/latency/step".into(),
            Series {
                steps: vec![0, 1, 2],
                values: vec![10.0, 11.0, 12.0],
            },
        );
        r.series.insert(
            "/latency/hop".into(),
            Series {
                steps: vec![1, 2, 3],
                values: vec![21.0, 22.0, 23.0],
            },
        );
        r
    }

    #[test]
    fn a_member_without_a_value_is_empty_absent_or_nan() {
        let dir = std::env::temp_dir().join(format!("uio-export-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (r, dt) = (lagging(), Some(0.5));
        super::export(&r, &dir.join("csv"), dt).unwrap();
        let csv = std::fs::read_to_string(dir.join("csv/latency.csv")).unwrap();
        assert_eq!(
            csv,
            "step,sim_time,hop [ns],step_latency [ns]\n0,0,,10\n1,0.5,21,11\n2,1,22,12\n3,1.5,23,\n"
        );

        super::npz::export(&r, &dir.join("x.npz"), dt).unwrap();
        let mut zip =
            zip::ZipArchive::new(std::fs::File::open(dir.join("x.npz")).unwrap()).unwrap();
        let mut bytes = Vec::new();
        zip.by_name("latency.npy")
            .unwrap()
            .read_to_end(&mut bytes)
            .unwrap();
        let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(npy.shape(), &[4, 2]);
        let got: Vec<u64> = npy
            .into_vec::<f64>()
            .unwrap()
            .iter()
            .map(|v| v.to_bits())
            .collect();
        let want: Vec<u64> = [f64::NAN, 21.0, 22.0, 23.0, 10.0, 11.0, 12.0, f64::NAN]
            .iter()
            .map(|v| v.to_bits())
            .collect();
        assert_eq!(got, want, "column by column: hop, then step_latency");

        super::mat::export(&r, &dir.join("x.mat"), dt).unwrap();
        let mat = std::fs::read(dir.join("x.mat")).unwrap();
        // The last variable is the group's; its data ends the file.
        let tail: Vec<u64> = mat[mat.len() - 64..]
            .chunks(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(tail, want);

        super::mcap::export(&r, &dir.join("x.mcap"), dt).unwrap();
        let data = std::fs::read(dir.join("x.mcap")).unwrap();
        let messages: Vec<(u64, String)> = mcap::MessageStream::new(&data)
            .unwrap()
            .map(|m| m.unwrap())
            .map(|m| (m.log_time, String::from_utf8(m.data.into_owned()).unwrap()))
            .collect();
        let want = [
            (0, r#"{"step":0,"sim_time":0.0,"step_latency":10.0}"#),
            (
                500_000_000,
                r#"{"step":1,"sim_time":0.5,"hop":21.0,"step_latency":11.0}"#,
            ),
            (
                1_000_000_000,
                r#"{"step":2,"sim_time":1.0,"hop":22.0,"step_latency":12.0}"#,
            ),
            (1_500_000_000, r#"{"step":3,"sim_time":1.5,"hop":23.0}"#),
        ];
        assert_eq!(messages, want.map(|(t, m)| (t, m.to_string())));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
