// Empty: this package only names the KTX-Software sources for `cargo vendor`.
