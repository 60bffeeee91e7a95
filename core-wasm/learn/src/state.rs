//! Sequential writer and validating reader of the flat state arrays
//! (see [`Model::state_sections`](crate::Model::state_sections)).

use crate::LearnError;

pub(crate) struct Writer<'a> {
    out: &'a mut [f64],
    at: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(out: &'a mut [f64], len: usize) -> Result<Self, LearnError> {
        if out.len() != len {
            return Err(LearnError::StateLength {
                section: "state",
                len: out.len(),
                expected: len,
            });
        }
        Ok(Writer { out, at: 0 })
    }

    pub(crate) fn put(&mut self, v: &[f64]) {
        self.out[self.at..self.at + v.len()].copy_from_slice(v);
        self.at += v.len();
    }

    pub(crate) fn take(&mut self, n: usize) -> &mut [f64] {
        let s = &mut self.out[self.at..self.at + n];
        self.at += n;
        s
    }
}

pub(crate) struct Reader<'a> {
    s: &'a [f64],
    at: usize,
    current: &'static str,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(s: &'a [f64], len: usize) -> Result<Self, LearnError> {
        if s.len() != len {
            return Err(LearnError::StateLength {
                section: "state",
                len: s.len(),
                expected: len,
            });
        }
        Ok(Reader {
            s,
            at: 0,
            current: "state",
        })
    }

    /// The next `len` values, all finite, as section `name`.
    pub(crate) fn section(
        &mut self,
        name: &'static str,
        len: usize,
    ) -> Result<&'a [f64], LearnError> {
        self.current = name;
        let v = &self.s[self.at..self.at + len];
        self.at += len;
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(self.bad(i, v[i], "a finite number"));
        }
        Ok(v)
    }

    /// An error about value `index` of the current section.
    pub(crate) fn bad(&self, index: usize, value: f64, expected: &'static str) -> LearnError {
        LearnError::StateValue {
            section: self.current,
            index,
            value,
            expected,
        }
    }
}
