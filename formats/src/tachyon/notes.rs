//! Features a scene uses that Luxon does not render as Tachyon does yet: one warning per
//! feature, at its first use, with the number of places that use it.

use std::collections::HashMap;

use crate::origin::{Origin, Spanned};

#[derive(Default)]
pub(super) struct Notes {
    /// Feature, what Luxon does instead, first use, number of uses.
    items: Vec<(String, String, Origin, usize)>,
    index: HashMap<String, usize>,
}

impl Notes {
    /// `what` (the feature, e.g. "OUTLINE") is used at `at`; `instead` says what Luxon does.
    pub fn add(&mut self, what: &str, instead: &str, at: &Origin) {
        match self.index.get(what) {
            Some(&i) => self.items[i].3 += 1,
            None => {
                self.index.insert(what.to_string(), self.items.len());
                self.items
                    .push((what.to_string(), instead.to_string(), at.clone(), 1));
            }
        }
    }

    /// One warning per feature, in order of first use.
    pub fn into_warnings(self) -> impl Iterator<Item = Spanned<String>> {
        self.items.into_iter().map(|(what, instead, at, n)| {
            let places = if n == 1 {
                String::new()
            } else {
                format!(" ({n} places; the first is here)")
            };
            Spanned {
                value: if instead.is_empty() {
                    format!("{what}{places}")
                } else {
                    format!("{what} {instead}{places}")
                },
                at,
            }
        })
    }
}
