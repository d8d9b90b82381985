//! The merge of a log's sources into one time-ordered stream of items, each source read
//! as the merge needs its next row.

use super::error::LogError;
use super::rows::{Dropped, SourceRows};
use super::schema::TimeOrder;
use crate::nav::session::Item;

/// The rows of one source still to come.
pub(super) enum Rows<'a> {
    Streamed(Box<SourceRows<'a>>),
    /// A source with `sort = true`, read whole and sorted.
    Sorted(std::vec::IntoIter<Item>),
}

/// The merged stream of a log's sources ([`Log::items`]): each source is read as the
/// merge needs its next row. A bad row ends the stream with its error, given right after
/// the row above it.
pub struct Items<'a> {
    /// The next item of each source (in the description's order), None once it is done.
    pub(super) heads: Vec<Option<Item>>,
    pub(super) rows: Vec<Rows<'a>>,
    /// 0 beacon positions, 1 measurements, 2 ground truth.
    pub(super) ranks: Vec<u8>,
    /// A source's error, given after the item in hand.
    pub(super) error: Option<LogError>,
    /// The damage of sources read whole (sorted) before the merge.
    pub(super) damaged: Vec<String>,
}

impl Items<'_> {
    /// What the sources could not read (a bag's truncation, its messages that did not
    /// decode), one line each naming the source.
    pub fn damage(&self) -> Vec<String> {
        let streamed = self.rows.iter().filter_map(|r| match r {
            Rows::Streamed(rows) => rows.table.damage().map(|d| format!("{}: {d}", rows.table.name())),
            Rows::Sorted(_) => None,
        });
        self.damaged.iter().cloned().chain(streamed).collect()
    }

    /// The rows dropped and kept so far by sources with `time_order = "drop"`.
    pub fn dropped(&self) -> Vec<Dropped> {
        self.rows
            .iter()
            .filter_map(|r| match r {
                Rows::Streamed(rows) if rows.order == TimeOrder::Drop => {
                    Some(Dropped { file: rows.table.name().to_string(), dropped: rows.dropped, kept: rows.kept_rows })
                }
                _ => None,
            })
            .collect()
    }
}

impl Iterator for Items<'_> {
    type Item = Result<Item, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        if let Some(e) = self.error.take() {
            self.heads.iter_mut().for_each(|h| *h = None);
            return Some(Err(e));
        }
        let key = |i: usize| self.heads[i].as_ref().map(|h| (h.t_s, self.ranks[i], i));
        let next = (0..self.heads.len())
            .filter_map(key)
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)))?
            .2;
        let refill = match &mut self.rows[next] {
            Rows::Streamed(rows) => rows.next_item(),
            Rows::Sorted(rows) => Ok(rows.next()),
        };
        match refill {
            Ok(head) => std::mem::replace(&mut self.heads[next], head).map(Ok),
            Err(e) => {
                // the item in hand first, the error at the next call, then the end
                self.error = Some(e);
                self.heads[next].take().map(Ok)
            }
        }
    }
}
