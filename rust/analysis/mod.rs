//! Analysis of runs: quasi-static load sharing.
