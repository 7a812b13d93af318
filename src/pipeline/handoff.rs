//! A prepared job as bytes, so that the page's other workers take the job worker's mesh
//! preparation instead of repeating it (docs/architecture.md, "The page's workers").
//!
//! [`Job::to_bytes`] writes the settings and the job's info (JSON), the repaired mesh, the
//! plane heights and the facet index (little-endian arrays); [`Job::from_bytes`] reads them
//! back into a job that plans every layer as the original does. The bytes never leave the
//! page, but they cross a message between workers: every length is checked against what is
//! left before anything is allocated, every number and index is checked, so damaged bytes are
//! refused with a message, never a panic or a job that slices wrongly.
//!
//! A *draft* ([`Draft`], [`Job::from_draft`]) is the same bytes with a provisional info, made
//! as soon as the job's parts are merged and indexed, before the passes that need the whole
//! mesh (the shells and their orientation, the repairs, the checks): the other workers slice
//! their first layers from it while the job worker finishes. The job worker then
//! sends a *confirmation* ([`Job::confirmation`], [`Job::confirm`]: the final settings and
//! info, a few kB) when its repairs left the mesh as drafted, else the whole prepared job.
//!
//! The bytes are written to a [`Sink`] and read from a [`Source`] a run of items at a time
//! through a small buffer: in the page, the sink and the source are the message's buffer
//! itself (outside the module's memory), so a worker never holds the job twice — once as its
//! arrays, once as their bytes — in a memory that never shrinks.

use super::Job;
use crate::base::error::Error;
use crate::base::parallel::RUN;
use crate::base::settings::Settings;
use crate::base::steps::{self, Budget};
use crate::model::mesh::Mesh;
use crate::model::prepare::JobInfo;
use crate::slicing::slice::FacetBuckets;

/// The first bytes: the format and its version.
const MAGIC: &[u8; 8] = b"DSJOB\0\0\x01";
/// The first bytes of a draft (the job's bytes with a provisional info).
const DRAFT_MAGIC: &[u8; 8] = b"DSDRAFT\x01";
/// The first bytes of a confirmation (the final settings and info of a drafted job).
const CONFIRM_MAGIC: &[u8; 8] = b"DSCONF\0\x01";

#[derive(serde::Serialize, serde::Deserialize)]
struct Meta {
    settings: Settings,
    info: JobInfo,
    /// Each instance's final move (not in the info's JSON, which the page also gets).
    shifts: Vec<[f64; 2]>,
}

/// Where [`Job::write_bytes`] writes: bytes at a place, every place written once.
pub trait Sink {
    fn write(&mut self, at: usize, bytes: &[u8]);
}

impl Sink for Vec<u8> {
    fn write(&mut self, at: usize, bytes: &[u8]) {
        self[at..at + bytes.len()].copy_from_slice(bytes);
    }
}

/// What [`Job::read_bytes`] reads: a length and bytes copied out at a place.
pub trait Source {
    /// How many bytes there are.
    fn size(&self) -> usize;
    /// Fills `out` with the bytes from `at` on (`at + out.len()` is within the length).
    fn read(&self, at: usize, out: &mut [u8]);
}

impl Source for &[u8] {
    fn size(&self) -> usize {
        <[u8]>::len(self)
    }
    fn read(&self, at: usize, out: &mut [u8]) {
        out.copy_from_slice(&self[at..at + out.len()]);
    }
}

impl Job {
    /// The prepared job as bytes for [`Job::from_bytes`] (about 24 B per vertex, 12 B per
    /// facet and 4 B per facet and layer it crosses).
    pub fn to_bytes(&self) -> Vec<u8> {
        bytes_of(self.bytes_writer())
    }

    /// The length of [`Job::to_bytes`] and what writes them into a sink of that length.
    pub fn bytes_writer(&self) -> (usize, impl FnOnce(&mut dyn Sink) + '_) {
        self.bytes_out().at_once()
    }

    /// [`Job::to_bytes`] to be written into a sink of [`BytesOut::size`] bytes, at once or
    /// in steps ([`BytesOut::write`]).
    pub fn bytes_out(&self) -> BytesOut<'_> {
        let (settings, info) = (&self.settings, &self.info);
        BytesOut::of(MAGIC, settings, info, &self.mesh, &self.zs, &self.buckets)
    }

    /// The job [`Job::to_bytes`] wrote. Bytes that are not such a job (truncated, of another
    /// version, with a number out of range or an index past its array) are refused as an
    /// internal error: they only ever come from another worker of the same page.
    pub fn from_bytes(bytes: &[u8]) -> Result<Job, Error> {
        Job::read_bytes(&bytes)
    }

    /// [`Job::from_bytes`] from any source of the bytes, read a run of items at a time.
    pub fn read_bytes(bytes: &dyn Source) -> Result<Job, Error> {
        steps::now(Job::take_in_steps(bytes, false, &steps::UNLIMITED))
    }

    /// [`Job::read_bytes`] (or, with `draft`, [`Job::from_draft`]) as a pass of `b`'s budget:
    /// the arrays read and checked in runs of items (the page's short calls). The same job,
    /// or the same refusal.
    pub async fn take_in_steps(bytes: &dyn Source, draft: bool, b: &Budget) -> Result<Job, Error> {
        let magic = if draft { DRAFT_MAGIC } else { MAGIC };
        read(bytes, magic, b).await.map_err(damaged)
    }

    /// The job of a [`Draft`]'s bytes: it slices as the finished job does if [`Job::confirm`] takes the job worker's confirmation, and is not to be
    /// used otherwise (its info is provisional). Damaged bytes are refused as by
    /// [`Job::read_bytes`].
    pub fn from_draft(bytes: &dyn Source) -> Result<Job, Error> {
        steps::now(Job::take_in_steps(bytes, true, &steps::UNLIMITED))
    }

    /// The confirmation of a drafted job for [`Job::confirm`]: its final settings and info
    /// (the facets, planes and index are the draft's).
    pub fn confirmation(&self) -> Vec<u8> {
        let meta = meta_json(&self.settings, &self.info);
        let mut out = Vec::with_capacity(CONFIRM_MAGIC.len() + 8 + meta.len());
        out.extend_from_slice(CONFIRM_MAGIC);
        out.extend_from_slice(&(meta.len() as u64).to_le_bytes());
        out.extend_from_slice(&meta);
        out
    }

    /// Takes the job worker's [`Job::confirmation`] into a job made by [`Job::from_draft`]:
    /// its final info. Refused (the job left as it was) unless the settings, the layers, the
    /// box and the units' facet runs are the draft's: those made its layers.
    pub fn confirm(&mut self, table: &dyn Source) -> Result<(), Error> {
        let confirm = |job: &mut Job| -> Result<(), String> {
            let mut r = Reader::new(table);
            let meta = r.header(CONFIRM_MAGIC, "not a confirmation of this version")?;
            if r.at != table.size() {
                return Err("bytes follow the confirmation".into());
            }
            let same_settings = serde_json::to_value(&meta.settings).ok()
                == serde_json::to_value(&job.settings).ok();
            if !same_settings {
                return Err("its settings are not the draft's".into());
            }
            let (old, new) = (&job.info, &meta.info);
            if new.layers != job.zs.len() || new.bounds != old.bounds || new.groups != old.groups {
                return Err("its layers, box or units' facets are not the draft's".into());
            }
            job.info = with_shifts(meta)?.1;
            Ok(())
        };
        confirm(self).map_err(damaged)
    }
}

/// A job as its parts were merged, before the passes that need the whole mesh: its
/// settings, the merged mesh, the plane heights, the facet index and a provisional info (no
/// mesh statistics, no warnings). [`Draft::bytes_writer`] writes the bytes of
/// [`Job::from_draft`].
pub struct Draft<'a> {
    pub(crate) settings: &'a Settings,
    pub(crate) info: JobInfo,
    pub(crate) mesh: &'a Mesh,
    pub(crate) zs: &'a [f64],
    pub(crate) index: &'a FacetBuckets,
}

impl Draft<'_> {
    /// The draft's bytes, for [`Job::from_draft`].
    pub fn to_bytes(&self) -> Vec<u8> {
        bytes_of(self.bytes_writer())
    }

    /// The length of the draft's bytes and what writes them into a sink of that length.
    pub fn bytes_writer(&self) -> (usize, impl FnOnce(&mut dyn Sink) + '_) {
        self.bytes_out().at_once()
    }

    /// The draft's bytes to be written, at once or in steps ([`BytesOut::write`]).
    pub fn bytes_out(&self) -> BytesOut<'_> {
        let (settings, info) = (self.settings, &self.info);
        BytesOut::of(DRAFT_MAGIC, settings, info, self.mesh, self.zs, self.index)
    }

    /// Hands the draft to `to`: to its hook at once, or written in runs of `b`'s budget into
    /// the sink it opens for the draft's length.
    pub(crate) async fn hand_to(&self, to: DraftTo, b: &Budget) {
        match to {
            DraftTo::Hook(hand) => hand(self),
            DraftTo::Steps(mut sink) => {
                let out = self.bytes_out();
                sink.open(out.size());
                out.write(sink.as_sink(), b).await;
                sink.done();
            }
        }
    }
}

/// What [`Job::prepare_drafted`] hands its [`Draft`] to (once): a function of it.
pub type DraftHook = Box<dyn FnOnce(&Draft<'_>)>;

/// Where [`Job::prepare_drafted_to`] hands its [`Draft`]: to a hook at once, or written in
/// steps into a [`DraftSink`] (the page: a buffer outside the module's memory).
pub enum DraftTo {
    Hook(DraftHook),
    Steps(Box<dyn DraftSink>),
}

/// A sink the draft is written into in steps: opened for the draft's length, told when
/// every byte is written.
pub trait DraftSink {
    fn open(&mut self, size: usize);
    fn as_sink(&mut self) -> &mut dyn Sink;
    fn done(&mut self);
}

/// The bytes a writer ([`Job::bytes_writer`], [`Draft::bytes_writer`]) writes.
fn bytes_of((size, write): (usize, impl FnOnce(&mut dyn Sink))) -> Vec<u8> {
    let mut out = vec![0u8; size];
    write(&mut out);
    out
}

fn damaged(e: String) -> Error {
    Error::Internal(format!(
        "the prepared job handed over is damaged: {e}; slice again"
    ))
}

fn meta_json(settings: &Settings, info: &JobInfo) -> Vec<u8> {
    serde_json::to_vec(&Meta {
        settings: settings.clone(),
        info: info.clone(),
        shifts: info.instances.iter().map(|i| i.shift).collect(),
    })
    .expect("settings and job info serialise")
}

/// The settings and the info with each instance's move put back.
fn with_shifts(meta: Meta) -> Result<(Settings, JobInfo), String> {
    let Meta {
        settings,
        mut info,
        shifts,
    } = meta;
    if shifts.len() != info.instances.len() {
        return Err("the instances' moves do not match the instances".into());
    }
    for (i, s) in info.instances.iter_mut().zip(shifts) {
        i.shift = s;
    }
    Ok((settings, info))
}

/// A job's bytes to be written (`index`: the facet index' rows): their length, and what
/// writes them into a sink of that length, at once or in steps.
pub struct BytesOut<'a> {
    magic: &'static [u8; 8],
    meta: Vec<u8>,
    mesh: &'a Mesh,
    zs: &'a [f64],
    index: (&'a [u32], &'a [u32]),
}

impl<'a> BytesOut<'a> {
    fn of(
        magic: &'static [u8; 8],
        settings: &Settings,
        info: &JobInfo,
        mesh: &'a Mesh,
        zs: &'a [f64],
        index: &'a FacetBuckets,
    ) -> BytesOut<'a> {
        BytesOut {
            magic,
            meta: meta_json(settings, info),
            mesh,
            zs,
            index: index.rows(),
        }
    }

    /// The length of the bytes.
    pub fn size(&self) -> usize {
        let rows = 16 + (self.index.0.len() + self.index.1.len()) * 4;
        self.magic.len()
            + 4 * 8
            + self.meta.len()
            + self.mesh.vertices.len() * 24
            + self.mesh.facets.len() * 12
            + self.zs.len() * 8
            + rows
    }

    /// The length and what writes the bytes at once.
    fn at_once(self) -> (usize, impl FnOnce(&mut dyn Sink) + 'a) {
        let size = self.size();
        let write = move |sink: &mut dyn Sink| steps::now(self.write(sink, &steps::UNLIMITED));
        (size, write)
    }

    /// Writes the bytes into `sink` (of [`BytesOut::size`] bytes), the arrays in runs of `b`'s
    /// budget.
    pub async fn write(&self, sink: &mut dyn Sink, b: &Budget) {
        let mut out = Writer { sink, at: 0 };
        out.bytes(self.magic);
        out.count(self.meta.len());
        out.bytes(&self.meta);
        out.count(self.mesh.vertices.len());
        out.put(self.mesh.vertices.as_flattened(), f64::to_le_bytes, b)
            .await;
        out.count(self.mesh.facets.len());
        out.put(self.mesh.facets.as_flattened(), u32::to_le_bytes, b)
            .await;
        out.count(self.zs.len());
        out.put(self.zs, f64::to_le_bytes, b).await;
        for row in [self.index.0, self.index.1] {
            out.count(row.len());
            out.put(row, u32::to_le_bytes, b).await;
        }
        debug_assert_eq!(out.at, self.size());
    }
}

/// The job of `magic`'s bytes: [`MAGIC`] (a prepared job) or [`DRAFT_MAGIC`] (a draft).
async fn read(bytes: &dyn Source, magic: &[u8; 8], b: &Budget) -> Result<Job, String> {
    let mut r = Reader::new(bytes);
    let meta = r.header(magic, "not a prepared job of this version")?;
    meta.settings.validate().map_err(|e| e.to_string())?;
    let n = r.count(24)?;
    let vertices: Vec<[f64; 3]> = r
        .get(n, b, |c: [u8; 24]| {
            std::array::from_fn(|k| f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().unwrap()))
        })
        .await;
    // Every vertex within the job's box (grown by 1 mm: the box is measured before the repair
    // closes cracks), so the work of every layer stays what the job worker's was.
    let (lo, hi) = (meta.info.bounds.min, meta.info.bounds.max);
    let boxed = |v: &[f64; 3]| (0..3).all(|k| v[k] >= lo[k] - 1.0 && v[k] <= hi[k] + 1.0);
    if !all(&vertices, b, boxed).await {
        return Err("a vertex lies outside the job's box".into());
    }
    let n = r.count(12)?;
    let facets: Vec<[u32; 3]> = r
        .get(n, b, |c: [u8; 12]| {
            std::array::from_fn(|k| u32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap()))
        })
        .await;
    if !all(&facets, b, |f| {
        f.iter().all(|&i| (i as usize) < vertices.len())
    })
    .await
    {
        return Err("a facet names a vertex past the last".into());
    }
    let n = r.count(8)?;
    let zs: Vec<f64> = r.get(n, b, f64::from_le_bytes).await;
    if zs.is_empty() || !zs.iter().all(|z| z.is_finite()) || zs.windows(2).any(|w| w[0] >= w[1]) {
        return Err("the plane heights are not finite and rising".into());
    }
    // Plane heights are above the part's lowest point.
    if zs[0] < 0.0 || zs[zs.len() - 1] > hi[2] - lo[2] + 1.0 {
        return Err("a plane lies outside the job's box".into());
    }
    if meta.info.layers != zs.len() {
        return Err("the layer count differs from the plane heights'".into());
    }
    let grouped: usize = meta.info.groups.iter().map(|g| g.facets).sum();
    if !meta.info.groups.is_empty() && grouped != facets.len() {
        return Err("the units' facet runs do not cover the mesh".into());
    }
    let mut rows = [Vec::new(), Vec::new()];
    for row in &mut rows {
        let n = r.count(4)?;
        *row = r.get(n, b, u32::from_le_bytes).await;
    }
    if r.at != bytes.size() {
        return Err("bytes follow the facet index".into());
    }
    let [offsets, bucket_facets] = rows;
    let buckets = FacetBuckets::from_rows(offsets, bucket_facets, zs.len(), facets.len())?;
    let (settings, info) = with_shifts(meta)?;
    Ok(Job::assemble(
        settings,
        Mesh { vertices, facets },
        buckets,
        zs,
        info,
    ))
}

/// Writes the bytes in order into a [`Sink`], a run of items at a time.
struct Writer<'a> {
    sink: &'a mut dyn Sink,
    at: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, b: &[u8]) {
        self.sink.write(self.at, b);
        self.at += b.len();
    }

    fn count(&mut self, n: usize) {
        self.bytes(&(n as u64).to_le_bytes());
    }

    /// `items` in the bytes `le` gives each, a run at a time through one buffer (in runs of
    /// `b`'s budget: [`steps::runs`]).
    async fn put<T: Copy, const N: usize>(
        &mut self,
        items: &[T],
        le: fn(T) -> [u8; N],
        b: &Budget,
    ) {
        let mut buf = vec![0u8; N * RUN.min(items.len())];
        steps::runs(items.len(), b, &mut |r| {
            let chunk = &mut buf[..N * r.len()];
            for (c, &x) in chunk.chunks_exact_mut(N).zip(&items[r]) {
                c.copy_from_slice(&le(x));
            }
            self.sink.write(self.at, chunk);
            self.at += chunk.len();
        })
        .await;
    }
}

/// Whether `ok` holds for every item (in runs of `b`'s budget: [`steps::runs`]).
async fn all<T>(items: &[T], b: &Budget, ok: impl Fn(&T) -> bool) -> bool {
    let mut all = true;
    steps::runs(items.len(), b, &mut |r| {
        all = all && items[r].iter().all(&ok)
    })
    .await;
    all
}

/// Reads the bytes in order; every length is checked against what is left.
struct Reader<'a> {
    bytes: &'a dyn Source,
    at: usize,
    /// The bytes last taken.
    buf: Vec<u8>,
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a dyn Source) -> Reader<'a> {
        Reader {
            bytes,
            at: 0,
            buf: Vec::new(),
        }
    }

    /// The first bytes, `magic` (else the error `wrong`), and the settings and info after
    /// them.
    fn header(&mut self, magic: &[u8; 8], wrong: &str) -> Result<Meta, String> {
        if self.take(magic.len())? != magic {
            return Err(wrong.into());
        }
        let n = self.count(1)?;
        serde_json::from_slice(self.take(n)?).map_err(|e| format!("its settings: {e}"))
    }

    /// The next `n` bytes (copied out of the source).
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.size())
            .ok_or("it ends early")?;
        self.buf.resize(n, 0);
        self.bytes.read(self.at, &mut self.buf);
        self.at = end;
        Ok(&self.buf)
    }

    /// A count of items of `size` bytes each that the bytes left can hold.
    fn count(&mut self, size: usize) -> Result<usize, String> {
        let n = u64::from_le_bytes(self.take(8)?.try_into().unwrap());
        let left = (self.bytes.size() - self.at) as u64;
        if n > left / size as u64 {
            return Err("a length runs past its end".into());
        }
        Ok(n as usize)
    }

    /// The next `n` items (checked by [`Reader::count`]), `N` bytes each, as `from` reads
    /// them: a run of items at a time through one buffer (in runs of `b`'s budget:
    /// [`steps::runs`]).
    async fn get<T, const N: usize>(
        &mut self,
        n: usize,
        b: &Budget,
        from: impl Fn([u8; N]) -> T,
    ) -> Vec<T> {
        let mut out = Vec::with_capacity(n);
        let mut buf = vec![0u8; N * RUN.min(n)];
        steps::runs(n, b, &mut |r| {
            let chunk = &mut buf[..N * r.len()];
            self.bytes.read(self.at, chunk);
            self.at += chunk.len();
            out.extend(
                chunk
                    .chunks_exact(N)
                    .map(|c| from(c.try_into().expect("N bytes"))),
            )
        })
        .await;
        out
    }
}
