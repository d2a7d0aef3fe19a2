"""The scenario: its schema (`schema`, with the APDS's dimensions in `dimensions`), loading and
writing (`loading`) and validation (`validation`). Imports no other wing."""
