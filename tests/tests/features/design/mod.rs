//! Designs: the report (text and JSON), controllers, real power-system models.

mod andes_models;
mod controllers;
mod report;
