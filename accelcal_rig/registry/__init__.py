"""The lab's memory: every finished calibration recorded by DUT serial, in a database named by a URL
(embedded SQLite by default, PostgreSQL for several rigs), its schema kept by Alembic migrations."""
