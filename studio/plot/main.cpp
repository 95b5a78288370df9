// tyndall-plot PLOTS.json [--out DIR]: draws each plot of {"plots": [{"file", "title", "xLabel", "yLabel", "xLog",
// "yLog", "series": [{"label", "x", "y", "yError"}]}]} as DIR/<file>.png and DIR/<file>.svg (DIR: the file's folder),
// all or nothing. Runs without a display (Qt's offscreen platform unless QT_QPA_PLATFORM says otherwise).
#include "plots.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"
#include "tyndall/project/project.h"

#include <QApplication>
#include <QDir>
#include <QFile>
#include <QTemporaryDir>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

using nlohmann::json;
using tyndall::InputError;
using tyndall::InputLocation;

tyndall::studio::DataPlotSpec specOf(const json& j, const std::string& file, std::size_t index) {
    const std::string field = "plots[" + std::to_string(index) + "]";
    try {
        tyndall::studio::DataPlotSpec spec;
        spec.title = QString::fromStdString(j.value("title", std::string()));
        spec.xLabel = QString::fromStdString(j.value("xLabel", std::string()));
        spec.yLabel = QString::fromStdString(j.value("yLabel", std::string()));
        spec.xLog = j.value("xLog", false);
        spec.yLog = j.value("yLog", false);
        for (const json& s : j.at("series")) {
            tyndall::studio::DataSeries series;
            series.label = QString::fromStdString(s.value("label", std::string()));
            series.x = s.at("x").get<std::vector<double>>();
            series.y = s.at("y").get<std::vector<double>>();
            if (s.contains("yError")) series.yError = s["yError"].get<std::vector<double>>();
            if (series.x.size() != series.y.size())
                throw InputError(InputLocation{file, 0, 0, field + ".series"}, "x and y must have as many values");
            spec.series.push_back(series);
        }
        return spec;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(InputLocation{file, 0, 0, field}, std::string("not a plot: ") + e.what());
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (qEnvironmentVariableIsEmpty("QT_QPA_PLATFORM")) qputenv("QT_QPA_PLATFORM", "offscreen");
    if (qEnvironmentVariableIsEmpty("XDG_RUNTIME_DIR")) {  // a batch job has none; Qt warns without one
        const std::string runtime =
            std::filesystem::temp_directory_path() / ("tyndall-runtime-" + std::to_string(::getuid()));
        ::mkdir(runtime.c_str(), 0700);
        qputenv("XDG_RUNTIME_DIR", runtime.c_str());
    }
    // The offscreen platform says that it cannot propagate size hints for every window: not a problem of the plots.
    qInstallMessageHandler([](QtMsgType, const QMessageLogContext&, const QString& message) {
        if (!message.contains("propagateSizeHints")) std::fprintf(stderr, "%s\n", qPrintable(message));
    });
    QApplication app(argc, argv);
    const QStringList args = app.arguments();
    if (args.size() != 2 && !(args.size() == 4 && args[2] == "--out")) {
        std::fprintf(stderr, "usage: tyndall-plot PLOTS.json [--out DIR]\n");
        return 2;
    }
    const std::string file = args[1].toStdString();
    try {
        const json doc = tyndall::readJsonFile(file, "plot description");
        if (!doc.is_object() || !doc.contains("plots") || !doc["plots"].is_array())
            throw InputError(InputLocation{file, 0, 0, "plots"}, "must be a list of plots");
        const std::filesystem::path out =
            args.size() == 4 ? std::filesystem::path(args[3].toStdString()) : std::filesystem::path(file).parent_path();
        QTemporaryDir scratch;  // Qt writes files by name; they are then staged into place together
        if (!scratch.isValid()) throw tyndall::OutputError("cannot create a temporary folder");
        tyndall::OutputSet files;
        std::vector<std::string> written;
        for (std::size_t i = 0; i < doc["plots"].size(); ++i) {
            const json& p = doc["plots"][i];
            const std::string name = p.value("file", std::string());
            if (name.empty() || name.find('/') != std::string::npos || name[0] == '.')
                throw InputError(InputLocation{file, 0, 0, "plots[" + std::to_string(i) + "].file"},
                                 "must be a plain file name without extension");
            tyndall::studio::DataPlot plot(QString::fromStdString(name));
            plot.setAttribute(Qt::WA_DontShowOnScreen);
            plot.resize(1200, 680);
            plot.show();  // lays the plot out at its size
            plot.draw(specOf(p, file, i));
            for (const char* ext : {".png", ".svg"}) {
                const QString temporary = scratch.filePath(QString::fromStdString(name) + ext);
                QString error;
                if (!plot.exportTo(temporary, &error)) throw tyndall::OutputError(error.toStdString());
                QFile f(temporary);
                if (!f.open(QIODevice::ReadOnly))
                    throw tyndall::OutputError("cannot read back " + temporary.toStdString());
                const QByteArray bytes = f.readAll();
                const std::string target = (out / (name + ext)).string();
                files.stage(target, std::string(bytes.constData(), std::size_t(bytes.size())));
                written.push_back(target);
            }
        }
        files.commit();
        for (const std::string& w : written)
            std::printf("wrote %s\n", w.c_str());
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "tyndall-plot: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tyndall-plot: error: %s\n", e.what());
        return 1;
    }
}
